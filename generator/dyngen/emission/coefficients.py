"""The base coefficients as text a reviewer can read and diff (coefficients.md)."""

from __future__ import annotations

import sympy as sp

from ..parameters import standard_in_dynamic_symbols
from .c_code import decimal_text


def grouped_text(row, names) -> str:
    """mz4 + my5 + 0.39*(m5 + m6 + m7): parameters sharing a coefficient are gathered."""
    groups = {}  # coefficient -> names, in order of first appearance
    for k, name in zip(row, names):
        if k != 0:
            groups.setdefault(k, []).append(name)
    terms = []
    for k, group in groups.items():
        if abs(k) == 1:
            terms += [(k, name) for name in group]
        else:
            body = group[0] if len(group) == 1 else "(" + " + ".join(group) + ")"
            size = decimal_text(abs(k)) if k.is_Rational else f"({abs(k)})"  # e.g. (sqrt(2)/2)
            terms.append((k, f"{size}*{body}"))
    text = ""
    for k, term in terms:
        if not text:
            text = term if k > 0 else f"-{term}"
        else:
            text += f" {'+' if k > 0 else '-'} {term}"
    return text


def dynamic_names_text(n_links: int) -> dict:
    """Standard symbol name -> its expression in dynamic parameters, compact (XX3 -> I3xx + m3*(c3y**2 + c3z**2))."""
    out = {}
    for sym, expr in standard_in_dynamic_symbols(n_links).items():
        text = str(sp.collect(expr, [s for s in expr.free_symbols if s.name.startswith("m")]))
        out[sym.name] = text if expr.is_Symbol or expr.is_Mul else f"({text})"
    return out
