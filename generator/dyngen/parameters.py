"""The two parametrisations of a link, their names and the one canonical order.

dynamic p (the paper's eqs. 2-5): m, c_x, c_y, c_z, I_xx, I_xy, I_xz, I_yy, I_yz, I_zz
    c in link frame i, I about the centre of mass with axes parallel to frame i.
standard s (linear in the dynamics, Khalil-Dombre): m, mx, my, mz, XX, XY, XZ, YY, YZ, ZZ
    (mx, my, mz) = m c, and XX..ZZ the inertia about the origin of frame i.
Both are stacked link by link, link 1 first; see docs/conventions.md.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

DYNAMIC_NAMES_PER_LINK = ("m", "cx", "cy", "cz", "Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz")
STANDARD_NAMES_PER_LINK = ("m", "mx", "my", "mz", "XX", "XY", "XZ", "YY", "YZ", "ZZ")
PER_LINK = len(DYNAMIC_NAMES_PER_LINK)

# Index of the symmetric 3x3 entries (row, col) in the 6-vector xx, xy, xz, yy, yz, zz.
_INERTIA_INDEX = {(0, 0): 0, (0, 1): 1, (0, 2): 2, (1, 1): 3, (1, 2): 4, (2, 2): 5}


def dynamic_name(link: int, k: int) -> str:
    """m3, c3x, I3xx: the letter, the link number (from 1), then the axes."""
    base = DYNAMIC_NAMES_PER_LINK[k]
    return f"{base[0]}{link}{base[1:]}"


def standard_name(link: int, k: int) -> str:
    """m3, mx3, XX3."""
    return f"{STANDARD_NAMES_PER_LINK[k]}{link}"


def dynamic_symbols(n_links: int) -> list[sp.Symbol]:
    return [sp.Symbol(dynamic_name(i + 1, k), real=True) for i in range(n_links) for k in range(PER_LINK)]


def standard_symbols(n_links: int) -> list[sp.Symbol]:
    return [sp.Symbol(standard_name(i + 1, k), real=True) for i in range(n_links) for k in range(PER_LINK)]


def inertia_matrix(six) -> sp.Matrix:
    """3x3 symmetric matrix from (xx, xy, xz, yy, yz, zz)."""
    return sp.Matrix(3, 3, lambda r, c: six[_INERTIA_INDEX[(min(r, c), max(r, c))]])


def standard_from_dynamic_link(p10):
    """Symbolic or numeric: one link's standard parameters from its dynamic ones."""
    m, cx, cy, cz, ixx, ixy, ixz, iyy, iyz, izz = p10
    return [
        m, m * cx, m * cy, m * cz,
        ixx + m * (cy * cy + cz * cz), ixy - m * cx * cy, ixz - m * cx * cz,
        iyy + m * (cx * cx + cz * cz), iyz - m * cy * cz,
        izz + m * (cx * cx + cy * cy),
    ]


def dynamic_from_standard_link(s10):
    """Inverse of standard_from_dynamic_link (needs m != 0)."""
    m, mx, my, mz, xx, xy, xz, yy, yz, zz = s10
    cx, cy, cz = mx / m, my / m, mz / m
    return [
        m, cx, cy, cz,
        xx - m * (cy * cy + cz * cz), xy + m * cx * cy, xz + m * cx * cz,
        yy - m * (cx * cx + cz * cz), yz + m * cy * cz,
        zz - m * (cx * cx + cy * cy),
    ]


def inertia_array(six) -> np.ndarray:
    """Numeric 3x3 symmetric matrix from (xx, xy, xz, yy, yz, zz)."""
    xx, xy, xz, yy, yz, zz = six
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)


def inertia_margin(entries) -> float:
    """lambda_min(tr(I)/2 E - I) of an inertia about the centre of mass, given as (xx, xy, xz,
    yy, yz, zz): tr(I)/2 - lambda_max(I), so >= 0 exactly when the principal moments meet the
    triangle inequalities (which make them non-negative too) and the pseudo-inertia is positive
    semidefinite. The one physical-consistency check of link parameters: the extraction's
    constraint and margin, identify's report and the diagnosis's payload use it."""
    inertia = inertia_array(entries)
    return float(np.linalg.eigvalsh(0.5 * np.trace(inertia) * np.eye(3) - inertia).min())


def consistency_margin(link10) -> float:
    """inertia_margin of one link's dynamic parameters (its inertia about the centre of mass)."""
    return inertia_margin(link10[4:10])


def consistency_problem(link10, tolerance: float = 0.0) -> str | None:
    """Why one link's dynamic parameters are no rigid body's, or None when they are one: m > 0,
    the inertia about the centre of mass positive definite (smallest principal moment above
    |tolerance| times the largest) and consistency_margin >= tolerance times the largest moment.
    A simulator's rounding is the tolerance: < 0 forgives round-off in parameters that are exactly
    on the boundary, > 0 keeps room from it for a program that checks in its own rounding."""
    m = float(link10[0])
    if not m > 0:
        return f"mass {m!r} is not positive"
    moments = [float(e) for e in np.linalg.eigvalsh(inertia_array(link10[4:10]))]
    largest = max(abs(moments[2]), np.finfo(float).tiny)
    listed = f"principal moments {moments[0]!r}, {moments[1]!r}, {moments[2]!r}"
    if not moments[0] > abs(tolerance) * largest:
        return f"inertia about the CoM is not positive definite ({listed})"
    if not consistency_margin(link10) >= tolerance * largest:
        return f"inertia about the CoM violates the triangle inequality A + B >= C ({listed}); no rigid body has it"
    return None


def standard_from_dynamic(p: np.ndarray) -> np.ndarray:
    """Numeric, all links: (10N,) dynamic -> (10N,) standard."""
    p = np.asarray(p, dtype=float).reshape(-1, PER_LINK)
    return np.array([standard_from_dynamic_link(row) for row in p], dtype=float).ravel()


def dynamic_from_standard(s: np.ndarray) -> np.ndarray:
    s = np.asarray(s, dtype=float).reshape(-1, PER_LINK)
    return np.array([dynamic_from_standard_link(row) for row in s], dtype=float).ravel()


def standard_in_dynamic_symbols(n_links: int) -> dict[sp.Symbol, sp.Expr]:
    """Each standard symbol as an expression of the dynamic symbols (mx3 -> c3x*m3)."""
    p = dynamic_symbols(n_links)
    s = standard_symbols(n_links)
    out = {}
    for i in range(n_links):
        exprs = standard_from_dynamic_link(p[PER_LINK * i: PER_LINK * (i + 1)])
        for k in range(PER_LINK):
            out[s[PER_LINK * i + k]] = sp.expand(exprs[k])
    return out
