"""Issue 24's emitter: the header's sincos macro (the bound it states) and the statement
scheduler (emission/schedule.py), each against an oracle of its own: numpy's sin and cos at the
same angles, and a count of live values done here by hand."""

from __future__ import annotations

import subprocess

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


@pytest.mark.parametrize("real, bound", [("double", 2.3e-16), ("float", 8e-8)])
def test_sincos_macro_against_numpy(real, bound, tmp_path):
    """The bound the header states, at 40000 angles up to 1e5 and at the quadrant edges; numpy's
    sin and cos of the same (float-rounded, in float) angle are the oracle."""
    source, exe = tmp_path / "probe.c", tmp_path / "probe"
    source.write_text(PROBE)
    flags = ["-DLWR_USE_FLOAT"] if real == "float" else []
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
