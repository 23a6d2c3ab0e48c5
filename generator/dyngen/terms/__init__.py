"""The torque terms: one definition of each, drawn on by identification's columns, the diagnosis's
candidates (its "effects"), excitation's information matrix and the emitted friction routine
(term.Term; a residual r = tau_measured - tau_model ~= sum over terms of columns @ values).

    offset, gain, time_shift   sensor.py   errors of the measurement
    coulomb, viscous, stribeck,
    direction                  friction.py per joint, of its own motion
    ripple, armature           rotor.py    the gear's harmonics, the rotor's inertia
    payload, coefficients      body.py     a body on the last link; the base regressor
    tilt, gravity_scale        tilt.py     gravity turned or scaled (from the joint model)"""

from __future__ import annotations

from .term import FrictionField, Term, Value
from .body import FixedShapePayload, Payload, RigidBody
from .context import Context
from .friction import (FRICTION_FIELDS, FRICTION_NAMES, IN_FRICTION, SCALE_VARIANTS, STRIBECK_VARIANTS, Coulomb,
                       Direction, Stribeck, Viscous, friction_torque)
from .rotor import Armature, Ripple
from .sensor import Gain, Offset, TimeShift
from .tilt import GravityScale, Tilt, gravity_matrix

TIME_SHIFTS = (0.001, 0.004, 0.016, 0.064)  # s: the variants tried (factors of 4; refined once selected)
TERMS = (Offset, Coulomb, Viscous, Stribeck, Direction, Ripple, Armature, Gain, Payload, Tilt, GravityScale,
         TimeShift, RigidBody)  # every term, in the diagnosis library's order
NAMES = tuple(term.name for term in TERMS)
# Errors in every base coefficient: dozens of values that fit anything a little, and over-fit
# real data (a repeated trajectory selects 43 of them). Tried only when asked for by name.
NOT_BY_DEFAULT = ("coefficients",)
DEFAULT_NAMES = tuple(name for name in NAMES if name not in NOT_BY_DEFAULT)


def check_names(names) -> None:
    """ValueError naming the unknown effect names, if any."""
    unknown = sorted(set(names) - set(NAMES))
    if unknown:
        raise ValueError(f"unknown effect(s) {', '.join(unknown)}; known: {', '.join(sorted(NAMES))}")


def effect_class(name: str) -> type:
    return next(term for term in TERMS if term.name == name)


def library(context: Context, names=None) -> list[Term]:
    """Every candidate tried by default (or those named), for one diagnosis (context)."""
    names = DEFAULT_NAMES if names is None else names
    check_names(names)
    candidates = [Offset(), *[Coulomb(v) for v in SCALE_VARIANTS], Viscous(), *[Stribeck(v) for v in STRIBECK_VARIANTS],
                  Direction(), Ripple(), Armature(), Gain(), Payload.of(context), Tilt.of(context),
                  GravityScale.of(context), *[TimeShift(dt) for dt in TIME_SHIFTS], RigidBody.of(context)]
    return [c for c in candidates if c.name in names]


__all__ = ["Armature", "Context", "Coulomb", "DEFAULT_NAMES", "Direction", "FRICTION_FIELDS", "FRICTION_NAMES",
           "FixedShapePayload", "FrictionField", "Gain", "GravityScale", "IN_FRICTION", "NAMES", "Offset", "Payload",
           "RigidBody", "Ripple", "Stribeck", "TERMS", "TIME_SHIFTS", "Term", "Tilt", "TimeShift", "Value", "Viscous",
           "check_names", "effect_class", "friction_torque", "gravity_matrix", "library"]
