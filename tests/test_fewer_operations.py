"""Issue 24's emitter: the header's sincos macro (the bound it states), the statement
scheduler (emission/schedule.py) and one product per function (emission/shared.py), each against
an oracle of its own: numpy's sin and cos at the same angles, a count of live values done here
by hand, and the emitted C text parsed here (not the emitter's sympy trees)."""

from __future__ import annotations

import re
import subprocess
from collections import Counter

import numpy as np
import pytest
import sympy as sp
from conftest import ROOT

from dyngen.derivation.program import Program
from dyngen.emission.schedule import scheduled

HEADER = ROOT / "generated" / "lwr"
PROBE = r"""
#include "lwr.h"
#include <stdio.h>
int main(void) {
  unsigned st = 12345u;
  for (long i = 0; i < 40000; ++i) {
    st = st * 1664525u + 1013904223u;
    double u = (double)st / 4294967296.0 - 0.5;
    /* a mix: large angles, moderate ones, joint-range ones, and next to the quadrant edges k pi/4 */
    double x = i % 4 == 0 ? u * 2e5 : i % 4 == 1 ? u * 8000.0 : i % 4 == 2 ? u * 20.0
             : (double)(i / 4 % 40 - 20) * 0.78539816339744831 + u * 1e-9;
    lwr_real xr = (lwr_real)x, s, c;
    LWR_SINCOS(xr, &s, &c);
    printf("%.17g %.17g %.17g\n", (double)xr, (double)s, (double)c);
  }
  return 0;
}
"""


@pytest.mark.parametrize("real, bound, more", [("double", 2.3e-16, []), ("float", 8e-8, []),
                                              ("double", 1e-10, ["-ffast-math"]), ("float", 1e-3, ["-ffast-math"])])
def test_sincos_macro_against_numpy(real, bound, more, tmp_path):
    """The bound the header states, at 40000 angles up to 1e5 and at the quadrant edges; numpy's
    sin and cos of the same (float-rounded, in float) angle are the oracle. With -ffast-math
    the header rounds to the quadrant through int (LWR_NEAREST: the compiler would cancel the two
    additions of 1.5 * 2^52, and every angle's reduction would be off by up to pi/4); the bound
    is then looser, as the compiler also reorders Cody-Waite's three subtractions (2e-11 in
    double, 5e-4 in float at |x| near 1e5)."""
    source, exe = tmp_path / "probe.c", tmp_path / "probe"
    source.write_text(PROBE)
    flags = (["-DLWR_USE_FLOAT"] if real == "float" else []) + more
    subprocess.run(["cc", "-std=c99", "-O2", *flags, f"-I{HEADER}", str(source), "-o", str(exe), "-lm"], check=True)
    rows = np.loadtxt(subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout.splitlines())
    x, s, c = rows.T
    assert np.abs(s - np.sin(x)).max() <= bound
    assert np.abs(c - np.cos(x)).max() <= bound
    assert np.abs(x).max() > 9e4  # the probe did reach large angles


def live_at_peak(order, outputs) -> int:
    """Largest number of values defined and still to be read, over the statements of `order`."""
    last = {}
    for k, a in enumerate(order):
        for s in a.expr.free_symbols:
            last[s] = k
    for s in outputs:
        last[s] = len(order)
    return max(sum(1 for a in order[:k + 1] if last.get(a.symbol, -1) > k) for k in range(len(order)))


def test_scheduler_keeps_dependencies_and_shortens_live_ranges():
    """Four independent products formed first and summed last (the order a recursion that
    forms its wrenches early writes) keep four values live; the scheduler sums each pair as soon
    as it exists. Every statement still comes after the ones it reads."""
    x = sp.symbols("a0:8", real=True)
    program = Program()
    products = [program.let(x[2 * k] * x[2 * k + 1]) for k in range(4)]
    sums = [program.let(products[0] + products[1] + x[0]), program.let(products[2] + products[3] + x[1])]
    out = program.let(sums[0] * sums[1])
    original = program.pruned([out])
    order = scheduled(original, {out}, {})
    assert sorted(a.symbol.name for a in order) == sorted(a.symbol.name for a in original)
    seen = set()
    for a in order:
        assert not (a.expr.free_symbols & {b.symbol for b in original}) - seen
        seen.add(a.symbol)
    assert live_at_peak(original, {out}) == 4
    assert live_at_peak(order, {out}) == 3


# ---- no product is formed twice: the emitted C parsed by a small parser of its own ----------

_TOKEN = re.compile(r"\s*(?:([A-Za-z_]\w*(?:\[\d+\])?)|(\d+\.\d*(?:[eE][-+]?\d+)?|\d+)|(\S))")
_FUNCTION = re.compile(r"^void (\w+)\(.*?\)\n\{\n(.*?)^\}", re.S | re.M)
_STATEMENT = re.compile(r"^\s*(?:const \w+ )?[\w\[\]]+ = (.*);\s*$")


class _Expression:
    """Recursive descent over C's + - * / unary minus, parentheses and calls. A product is a chain
    of * (parentheses flattened, signs dropped), named by its sorted factors' texts."""

    def __init__(self, text: str):
        self.tokens = [m.group(1) or m.group(2) or m.group(3) for m in _TOKEN.finditer(text)]
        self.k, self.products = 0, []
        self.sum()

    def peek(self):
        return self.tokens[self.k] if self.k < len(self.tokens) else ""

    def take(self):
        self.k += 1
        return self.tokens[self.k - 1]

    def sum(self):
        terms = [self.product()]
        while self.peek() in ("+", "-"):
            self.take()
            terms.append(self.product())
        return "(" + "+".join(sorted(terms)) + ")" if len(terms) > 1 else terms[0]

    def product(self):
        factors = [self.unary()]
        while self.peek() in ("*", "/"):
            factors.append(("1/" if self.take() == "/" else "") + self.unary())
        if len(factors) == 1:
            return factors[0]
        flat = sorted(f for factor in factors for f in factor.split("*"))  # nested chains: one product
        self.products.append("*".join(flat))
        return "*".join(flat)

    def unary(self):
        if self.peek() == "-":
            self.take()
            return self.unary()
        token = self.take()
        if token == "(":
            inner = self.sum()
            self.take()
            return inner if "*" not in inner or inner.startswith("(") else f"({inner})"
        if self.peek() == "(":  # a call: the cast macro LWR_K(0.5), LWR_SIN(...)
            self.take()
            before = len(self.products)
            inner = self.sum()
            self.take()
            if token.endswith("_K"):  # a constant like 500.0/77.0, folded by the compiler
                del self.products[before:]
            return f"{token}({inner})"
        return token


def repeated_products(c_text: str) -> dict:
    """{function: {product: times formed}} for the products formed more than once."""
    found = {}
    for name, body in _FUNCTION.findall(c_text):
        products = Counter()
        for line in body.splitlines():
            statement = _STATEMENT.match(line)
            if statement and "for (" not in line:
                products.update(_Expression(statement.group(1)).products)
        twice = {p: k for p, k in products.items() if k > 1}
        if twice:
            found[name] = twice
    return found


def test_the_parser_sees_a_repeated_product():
    """The oracle itself: a b formed in two statements (one nested, one with a sign) is found."""
    text = "void f(void)\n{\n    const double x0 = c*(a*b + d);\n    const double x1 = -b*a - 2*x0;\n}\n"
    assert repeated_products(text) == {"f": {"a*b": 2}}
    assert repeated_products(text.replace("-b*a", "-b*d")) == {}


@pytest.mark.parametrize("arm", ["lwr", "stanford"])
def test_no_product_is_formed_twice(arm):
    """Every emitted function of generated/ (dynamics, regressors, controller functions,
    derivatives, parameters): a product of the same factors is formed once and read again.
    Before emission/shared.py the LWR's mass matrix formed 42 products twice (s66 c7 in the
    composite body's moment and again in the wrench carried to joint 6)."""
    sources = sorted((ROOT / "generated" / arm).glob("*.c"))
    assert len(sources) > 8
    functions = sum(len(_FUNCTION.findall(path.read_text())) for path in sources)
    assert functions > 20  # the parser did find the functions
    repeated = {path.name: r for path in sources if (r := repeated_products(path.read_text()))}
    assert repeated == {}
