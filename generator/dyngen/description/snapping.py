"""Exact constants from a URDF's decimals: angles near a multiple of pi/12 become it, axis
components near 0 or +-1 become them, lengths are their decimal value (0.333 -> 333/1000).

URDFs write pi/2 as 1.5708 or 1.570796 and axes as `0 -1 0.0000001`; a count computed from the
rounded numbers is wrong (the twist is then not a right angle, and terms that cancel for the
real arm do not). Every snap is recorded (joint, field, from, to) for the terminal and the
manifest; `--no-snap` keeps the numbers as written (description/angles.py then makes each
angle an exact rational point of the circle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import sympy as sp

ANGLE_TOLERANCE = 1e-4  # rad: 3.1416 - pi = 7e-6, 1.5708 - pi/2 = 4e-6; no real design angle is this close
AXIS_TOLERANCE = 1e-4  # a component this close to 0 or +-1 is that value
STEP = sp.pi / 12


@dataclass(frozen=True)
class Snap:
    joint: str
    field: str  # e.g. origin.rpy[2], axis
    before: str  # as written
    after: str  # the exact value used


def allowed(snap, joint: str, field: str) -> bool:
    """snap: True, False, or a frozenset of (joint, field) to keep as written (snap_effect.py)."""
    return snap is True or (isinstance(snap, frozenset) and (joint, field) not in snap)


def length(text: str) -> sp.Rational:
    return sp.Rational(text)


def angle(text: str, joint: str, field: str, snaps: list, snap: bool = True) -> sp.Expr:
    value = float(text)
    k = round(value / float(STEP))
    exact = k * STEP
    if abs(value - float(exact)) <= 1e-15 * max(1.0, abs(value)) or value == 0:
        return exact if value != 0 else sp.Integer(0)
    if allowed(snap, joint, field) and abs(value - float(exact)) <= ANGLE_TOLERANCE:
        snaps.append(Snap(joint, field, text, str(exact)))
        return exact
    return sp.Rational(text)


def axis(texts, joint: str, snaps: list, snap: bool = True) -> tuple:
    """The unit axis: exact when every component snaps (the usual case), else (floats) normalised."""
    values = [float(t) for t in texts]
    norm = math.sqrt(sum(v * v for v in values))
    unit = [v / norm for v in values]
    snapped = [0 if abs(u) <= AXIS_TOLERANCE else (1 if abs(u - 1) <= AXIS_TOLERANCE else
               -1 if abs(u + 1) <= AXIS_TOLERANCE else None) for u in unit]
    if None not in snapped and sum(abs(s) for s in snapped) == 1:
        if snapped != values:
            if allowed(snap, joint, "axis"):
                snaps.append(Snap(joint, "axis", " ".join(texts), " ".join(str(s) for s in snapped)))
            else:
                return tuple(unit)
        return tuple(sp.Integer(s) for s in snapped)
    return tuple(unit)
