"""Operation counts of emitted code, counted as the C printer writes it.

x*y*z is 2 multiplications, 2*x one, -x none (a sign flip); x**2 is one (printed x*x);
a+b-c is 2 additions; x/y one division; sin and cos are counted apiece inside expressions. The
emitted functions count their joint angles per library call: the sin and cos of one angle are
one call (sincos, emission/c_code.py).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import sympy as sp


@dataclass(frozen=True)
class OpCount:
    mul: int = 0
    add: int = 0
    div: int = 0
    trig: int = 0

    def __add__(self, other):
        return OpCount(self.mul + other.mul, self.add + other.add, self.div + other.div, self.trig + other.trig)

    def __str__(self):
        return f"{self.mul} mul, {self.add} add, {self.div} div, {self.trig} sin/cos"


def count(expr) -> OpCount:
    c = Counter()
    _count(sp.sympify(expr), c)
    return OpCount(c["mul"], c["add"], c["div"], c["trig"])


def count_all(exprs) -> OpCount:
    total = OpCount()
    for e in exprs:
        total = total + count(e)
    return total


def _count(e, c):
    if e.is_Atom:
        return
    if e.is_Add:
        c["add"] += len(e.args) - 1
    elif e.is_Mul:
        coeff, factors = e.as_coeff_mul()
        constants = [f for f in factors if f.is_number]  # sqrt(2)/2*x: one constant factor (as printed)
        if constants:
            coeff, factors = sp.Mul(coeff, *constants), tuple(f for f in factors if not f.is_number)
        denominators = [f for f in factors if f.is_Pow and f.exp.is_negative]
        numerators = len(factors) - len(denominators) + (0 if abs(coeff) == 1 else 1)
        c["mul"] += max(numerators - 1, 0) + max(len(denominators) - 1, 0)
        c["div"] += 1 if denominators else 0
        for f in factors:
            _count(f.base if f in denominators else f, c)
        return
    elif e.is_Pow:
        if e.exp.is_Integer and e.exp > 0:
            c["mul"] += int(e.exp) - 1
        elif e.exp == -1:
            c["div"] += 1
        _count(e.base, c)
        return
    elif isinstance(e, (sp.sin, sp.cos)):
        c["trig"] += 1
    for arg in e.args:
        _count(arg, c)
