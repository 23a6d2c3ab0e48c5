"""Fewer multiplications in a sum: common factors taken out, greedily (a Horner-like form).

p*a + p*b - q*c + q*d  ->  p*(a + b) + q*(d - c), and 0.4*a + 0.4*b -> 0.4*(a + b): the recursion's link wrenches are sums of
parameter times motion terms, with each parameter in several terms (J wd and w x (J w) both
carry XY, XZ, ...). The value is the same polynomial: only the order of the floating-point
operations changes (no cancellation is introduced: every term keeps its own product).
"""

from __future__ import annotations

from collections import Counter

import sympy as sp


def factored(expr: sp.Expr) -> sp.Expr:
    """expr with, in every sum, the symbol common to most terms (at least 2) taken out, recursively."""
    if expr.is_Atom:
        return expr
    if expr.is_Add:
        return _factor_sum(list(expr.args))
    if expr.is_Mul or expr.is_Pow:
        return expr.func(*(factored(a) for a in expr.args), evaluate=False) if any(a.is_Add for a in expr.args) \
            else expr
    return expr.func(*(factored(a) for a in expr.args))


def _factors_of(term) -> list:
    """What can be taken out of one product term: its symbol factors (power 1) and the size of
    its numeric coefficient when that is not 1 (0.4 a + 0.4 b -> 0.4 (a + b))."""
    coeff, rest = term.as_coeff_Mul()
    out = [abs(coeff)] if coeff.is_Number and abs(coeff) != 1 else []
    if rest.is_Symbol:
        out.append(rest)
    elif rest.is_Mul:
        out += [f for f in rest.args if f.is_Symbol]
    return out


def _factor_sum(terms: list) -> sp.Expr:
    counts = Counter(f for t in terms for f in set(_factors_of(t)))
    if not counts or max(counts.values()) < 2:
        return sp.Add(*(factored(t) for t in terms))
    best = max(sorted(counts, key=lambda f: (f.is_Number, str(f))), key=lambda f: counts[f])  # ties: symbols first
    inside = [t for t in terms if best in _factors_of(t)]
    rest = [t for t in terms if best not in _factors_of(t)]
    common = _factor_sum([t / best for t in inside])
    grouped = sp.Mul(best, common, evaluate=False) if common.is_Add else best * common
    return sp.Add(grouped, _factor_sum(rest), evaluate=False) if rest else grouped
