"""Identified coefficients, in any basis and order, as targets W pi(p) = v in dyngen's basis.

A user's coefficient is an expression in dynamic ("c7y*m7") or standard ("my7") names. It
becomes a linear form u over the standard parameters; it is identifiable exactly when u is
a combination w of the rows of K (pi = K s), and since K is the identity on its pivot
columns, w = u[pivots] and the check u == w K is exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..description.expressions import ExpressionError, parse_expression, shorten
from ..errors import InputError
from ..parameters import PER_LINK, dynamic_symbols, standard_symbols


@dataclass
class Target:
    kind: str
    W: np.ndarray  # (rows, rank)
    v: np.ndarray  # (rows,)


def linear_form(text: str, n_links: int) -> list:
    """Exact coefficients over the standard parameters of one coefficient expression."""
    s = standard_symbols(n_links)
    p = dynamic_symbols(n_links)
    names = {sym.name: sym for sym in s + p}
    expr = parse_expression(text, names)  # whitelisted: nothing in the text runs
    # dynamic -> standard: c = mc/m, I_c = J - m (c.c E - c c^T)
    subs = {}
    for i in range(n_links):
        m, mx, my, mz, XX, XY, XZ, YY, YZ, ZZ = s[PER_LINK * i: PER_LINK * (i + 1)]
        _, cx, cy, cz, ixx, ixy, ixz, iyy, iyz, izz = p[PER_LINK * i: PER_LINK * (i + 1)]
        subs.update({p[PER_LINK * i]: m, cx: mx / m, cy: my / m, cz: mz / m,
                     ixx: XX - (my**2 + mz**2) / m, iyy: YY - (mx**2 + mz**2) / m, izz: ZZ - (mx**2 + my**2) / m,
                     ixy: XY + mx * my / m, ixz: XZ + mx * mz / m, iyz: YZ + my * mz / m})
    linear = sp.expand(sp.cancel(expr.xreplace(subs)))
    poly = sp.Poly(linear, *s)
    if poly.total_degree() > 1 or poly.coeff_monomial(1) != 0:
        raise ValueError("not a linear combination of standard parameters")
    return [poly.coeff_monomial(sym) for sym in s]


def target(robot, base, kind: str) -> Target | None:
    entries = robot.identified.get(kind)
    if not entries:
        return None
    K = [list(row) for row in base.K]
    W, v = [], []
    for k, entry in enumerate(entries):
        field = f"identified.{kind}[{k}].coefficient"
        try:
            u = linear_form(entry.coefficient, robot.dof)
        except (ExpressionError, ValueError, TypeError, sp.PolynomialError) as err:
            raise InputError(robot.source, field, f'cannot use "{shorten(entry.coefficient)}": {err}') from None
        w = [u[j] for j in base.pivots]
        rebuilt = [sum(w[r] * K[r][j] for r in range(len(K))) for j in range(len(u))]
        if any(a != b for a, b in zip(rebuilt, u)):
            raise InputError(robot.source, field, f'"{shorten(entry.coefficient)}" is not identifiable from the '
                             f"{kind} dynamics (not a combination of its base coefficients)")
        W.append([float(x) for x in w])
        v.append(entry.value)
    return Target(kind, np.array(W), np.array(v))
