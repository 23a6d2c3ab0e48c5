"""The library of candidate unmodelled effects, each a small model of the residual
r = tau_measured - tau_model that is linear in its fitted values:

    r ~= sum over effects of columns(context, signals) @ values

An effect acts either on one joint at a time (scope "joint": friction, rotor inertia, sensor
offset and gain; one candidate per joint) or on the whole arm with shared values (scope
"arm": payload, tilted base, time shift, errors in the model's coefficients). Nonlinear
parameters (the Stribeck velocity, the time shift of the exact form) are handled as a few
fixed variants of one effect, refined once the effect is selected (diagnosis/refine.py).
"""

from __future__ import annotations

from ...terms.friction import SCALE_VARIANTS as COULOMB_VELOCITIES
from ...terms.friction import STRIBECK_VARIANTS as STRIBECK_VELOCITIES
from .base import Context, Effect
from .body import Coefficients, Payload
from .friction import Armature, Coulomb, Direction, Ripple, Stribeck, Viscous
from .sensor import Gain, Offset, TimeShift
from .tilt import GravityScale, Tilt, gravity_matrix

TIME_SHIFTS = (0.001, 0.004, 0.016, 0.064)  # s: the variants tried (factors of 4; refined once selected)
# Errors in every base coefficient: dozens of values that fit anything a little, and over-fit
# real data (a repeated trajectory selects 43 of them). Tried only when asked for by name.
NOT_BY_DEFAULT = ("coefficients",)
EFFECTS = (Offset, Coulomb, Viscous, Stribeck, Direction, Ripple, Armature, Gain, Payload, Tilt, GravityScale,
           TimeShift, Coefficients)  # every effect class, in the library's order
NAMES = tuple(cls.name for cls in EFFECTS)
DEFAULT_NAMES = tuple(name for name in NAMES if name not in NOT_BY_DEFAULT)


def check_names(names) -> None:
    """ValueError naming the unknown effect names, if any."""
    unknown = sorted(set(names) - set(NAMES))
    if unknown:
        raise ValueError(f"unknown effect(s) {', '.join(unknown)}; known: {', '.join(sorted(NAMES))}")


def effect_class(name: str) -> type:
    """The class of the effect a report entry names (FixedShapePayload reports as "payload")."""
    return next(cls for cls in EFFECTS if cls.name == name)


def library(context: Context, names=None) -> list[Effect]:
    """Every candidate effect tried by default (or those whose name is in `names`), for the
    diagnosis of one robot and its link parameters (context)."""
    names = DEFAULT_NAMES if names is None else names
    check_names(names)
    effects = [Offset(), *[Coulomb(v) for v in COULOMB_VELOCITIES], Viscous(),
               *[Stribeck(v) for v in STRIBECK_VELOCITIES], Direction(), Ripple(), Armature(), Gain(),
               Payload.of(context), Tilt.of(context), GravityScale.of(context), *[TimeShift(dt) for dt in TIME_SHIFTS],
               Coefficients.of(context)]
    return [e for e in effects if e.name in names]


__all__ = ["Armature", "Coefficients", "Context", "Coulomb", "Direction", "Effect", "Gain", "GravityScale", "Offset",
           "Payload", "Ripple", "Stribeck", "Tilt", "TimeShift", "Viscous", "check_names", "effect_class",
           "gravity_matrix", "library", "COULOMB_VELOCITIES", "DEFAULT_NAMES", "EFFECTS", "NAMES",
           "STRIBECK_VELOCITIES", "TIME_SHIFTS"]
