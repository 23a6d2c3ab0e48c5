"""The extraction problem: bounds, references, stages, identities, and feasibility checks.

Before any optimisation, bounds that no physically consistent parameters can satisfy are
reported by name (a link's inertia box against the triangle inequalities, the link mass
bounds against the total mass), so that no "solution" violating them is ever printed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from scipy.optimize import linprog

from ..description.expressions import ExpressionError, parse_expression, shorten
from ..description.extraction_options import Options  # noqa: F401  (re-exported: the problem is built from them)
from ..errors import Infeasible, InputError
from ..parameters import PER_LINK, consistency_margin, dynamic_name, dynamic_symbols, inertia_margin
from .targets import Target


@dataclass
class Stage:
    name: str
    blocks: list[Target]
    free: np.ndarray  # bool (10N,)
    value: np.ndarray  # values of the fixed parameters (and the reference start)
    # the next stage's targets: among this stage's best fits, the driver returns the one that fits
    # these best (the next stage keeps part of it fixed)
    next_blocks: list[Target] = field(default_factory=list)
    # among this stage's equally good fits, return the one nearest the reference (off: the fit
    # itself, which is all a cross-validation's fits need, at a third of the time)
    nearest: bool = True


@dataclass
class Problem:
    n_links: int
    lower: np.ndarray
    upper: np.ndarray
    reference: np.ndarray
    weight: np.ndarray
    total_mass: tuple | None
    equalities: list = field(default_factory=list)  # [[(coefficient, [indices])]]
    center: np.ndarray | None = None  # strictly inside the bounds and consistency (see strict_center)


def bounds(robot, options: Options) -> tuple[np.ndarray, np.ndarray]:
    if robot.lower is None:
        raise InputError(robot.source, "parameters.bounds", "missing: extraction needs LB/UB for every parameter")
    lower = np.array([v for link in robot.lower for v in link.as_tuple()])
    upper = np.array([v for link in robot.upper for v in link.as_tuple()])
    masses = np.arange(0, lower.size, PER_LINK)
    lower[masses] = np.maximum(lower[masses], options.mass_margin)  # a link has positive mass
    return lower, upper


def build_problem(robot, options: Options) -> Problem:
    lower, upper = bounds(robot, options)
    if robot.nominal is not None:
        reference = np.clip([v for link in robot.nominal for v in link.as_tuple()], lower, upper)
    else:
        reference = 0.5 * (lower + upper)
    span = np.maximum(upper - lower, 1e-12)
    problem = Problem(robot.dof, lower, upper, reference, 1.0 / span**2, robot.total_mass)
    problem.equalities = [identity_terms(text, robot) for text in options.identities]
    check_feasible(problem, options, robot.source)
    problem.center = strict_center(problem, options)
    return problem


def identity_terms(text: str, robot) -> list:
    """'I7xz = c7x*c7z*m7' -> polynomial terms [(coefficient, [parameter indices])] of lhs - rhs."""
    p = dynamic_symbols(robot.dof)
    names = {s.name: s for s in p}
    try:
        lhs, rhs = text.split("=")
        poly = sp.Poly(parse_expression(lhs, names) - parse_expression(rhs, names), *p)  # nothing in it runs
    except ExpressionError as err:
        raise InputError(robot.source, "identities", f"expected a polynomial in parameter names, {err}") from None
    except (ValueError, sp.PolynomialError):
        raise InputError(robot.source, "identities",
                         f'expected "parameter expression = expression", got "{shorten(text)}"') from None
    terms = []
    for monomial, coefficient in zip(poly.monoms(), poly.coeffs()):
        indices = [j for j, power in enumerate(monomial) for _ in range(power)]
        terms.append((float(coefficient), indices))
    return terms


def check_feasible(problem: Problem, options: Options, source: str) -> None:
    conflicts = []
    for link in range(problem.n_links):
        margin = best_inertia_margin(problem.lower, problem.upper, link)
        if margin < options.margin:
            names = ", ".join(dynamic_name(link + 1, k) for k in range(4, 10))
            conflicts.append(f"link {link + 1}: the bounds of {names} admit no physically consistent inertia "
                             f"(largest reachable smallest eigenvalue of tr(I)/2 E - I: {margin:.3g} < margin "
                             f"{options.margin:g}; e.g. Ixx + Iyy >= Izz cannot hold)")
    if problem.total_mass is not None:
        lo, hi = problem.total_mass
        m_lo = problem.lower[::PER_LINK].sum()
        m_hi = problem.upper[::PER_LINK].sum()
        if m_lo > hi or m_hi < lo:
            conflicts.append(f"parameters.total_mass [{lo:g}, {hi:g}] conflicts with the link mass bounds "
                             f"(their sum lies in [{m_lo:g}, {m_hi:g}])")
    if conflicts:
        raise Infeasible(f"{source}: infeasible bounds: " + "; ".join(conflicts))


def best_inertia_margin(lower, upper, link: int) -> float:
    """max over the box of lambda_min(tr(I)/2 E - I), with the diagonal chosen by a small LP and
    the products of inertia as close to zero as their bounds allow (a lower bound of the maximum)."""
    return most_consistent_inertia(lower, upper, link)[1]


def most_consistent_inertia(lower, upper, link: int) -> tuple[np.ndarray, float]:
    """(xx, xy, xz, yy, yz, zz) of best_inertia_margin's inertia, and its margin (-inf: none)."""
    base = PER_LINK * link + 4
    lo, hi = lower[base: base + 6], upper[base: base + 6]
    diag = [0, 3, 5]  # xx, yy, zz
    # maximise t: (sum - 2 I_kk)/2 >= t for k = x, y, z; variables (xx, yy, zz, t)
    A, b = [], []
    for k in range(3):
        row = [-0.5] * 3 + [1.0]
        row[k] = 0.5
        A.append(row)
        b.append(0.0)
    result = linprog(c=[0, 0, 0, -1], A_ub=A, b_ub=b,
                     bounds=[(lo[d], hi[d]) for d in diag] + [(None, None)], method="highs")
    if not result.success:
        return 0.5 * (lo + hi), -np.inf
    xx, yy, zz = result.x[:3]
    xy, xz, yz = (float(np.clip(0.0, lo[k], hi[k])) for k in (1, 2, 4))
    entries = np.array([xx, xy, xz, yy, yz, zz])
    return entries, inertia_margin(entries)


def strict_center(problem: Problem, options: Options) -> np.ndarray:
    """Parameters strictly inside every bound and strictly consistent where the bounds allow: the
    driver's barrier method starts from points pulled towards it. Masses and centres of mass at the
    middle of their bounds (the driver moves the masses into the total-mass window); per link the
    inertia at the middle of its box if that is consistent with room to spare, else the mix of the
    middle with the most consistent inertia (consistency is concave in I, so the mix keeps part of
    its margin while leaving the box's faces)."""
    center = 0.5 * (problem.lower + problem.upper)
    for link in range(problem.n_links):
        base = PER_LINK * link + 4
        best, best_margin = most_consistent_inertia(problem.lower, problem.upper, link)
        middle = center[base: base + 6].copy()
        for t in (1.0, 0.5, 0.25, 0.1, 0.01):
            mix = t * middle + (1 - t) * best
            if inertia_margin(mix) > options.margin + 0.5 * max(best_margin - options.margin, 0.0):
                center[base: base + 6] = mix
                break
        else:
            center[base: base + 6] = best
    return center


def is_consistent(p: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """Per link: mass > 0 and lambda_min(tr(I)/2 E - I) >= margin (the pseudo-inertia is positive)."""
    out = []
    for link in np.asarray(p, dtype=float).reshape(-1, PER_LINK):
        out.append(link[0] > 0 and consistency_margin(link) >= margin)
    return np.array(out)


def pinned(problem, p, rel: float = 1e-6) -> list:
    """Names of the parameters at (within rel of the range from) one of their bounds."""
    span = np.maximum(problem.upper - problem.lower, 1e-300)
    at = (np.abs(p - problem.lower) < rel * span) | (np.abs(problem.upper - p) < rel * span)
    return [dynamic_name(j // PER_LINK + 1, j % PER_LINK) for j in np.flatnonzero(at)]
