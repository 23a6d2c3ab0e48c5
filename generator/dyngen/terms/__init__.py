"""The torque terms: one definition of each, drawn on by identification's columns, the
diagnosis's candidates, excitation's information matrix and the emitted friction routine.

Each term (base.Term) states its fitted values and their physical ranges (base.Value), its
nonlinear settings, its regressor columns (numpy, per chunk of samples where `pointwise`), its
documentation line, and for the friction routine its fields and its C (friction.IN_FRICTION):
the firmware's friction is, by construction, the law that was fitted.

    rigid_body, payload        body.py     the base regressor; a body on the last link
    coulomb, viscous, stribeck,
    direction, ripple, armature friction.py  per joint, of its own motion
    offset, gain, time_shift   sensor.py   errors of the measurement
    tilt, gravity_scale        tilt.py     gravity turned or scaled (from the joint model)
"""

from __future__ import annotations

from .base import FrictionField, Term, Value
from .body import Payload, RigidBody
from .friction import (FRICTION_FIELDS, FRICTION_NAMES, IN_FRICTION, Armature, Coulomb, Direction, Ripple, Stribeck,
                       Viscous, friction_torque)
from .sensor import Gain, Offset, TimeShift
from .tilt import GravityScale, Tilt

TERMS = (RigidBody, Offset, Coulomb, Viscous, Stribeck, Direction, Ripple, Armature, Payload, Tilt, GravityScale,
         TimeShift, Gain)
BY_NAME = {term.name: term for term in TERMS}

__all__ = ["Armature", "BY_NAME", "Coulomb", "Direction", "FRICTION_FIELDS", "FRICTION_NAMES", "FrictionField", "Gain",
           "GravityScale", "IN_FRICTION", "Offset", "Payload", "RigidBody", "Ripple", "Stribeck", "TERMS", "Term",
           "Tilt", "TimeShift", "Value", "Viscous", "friction_torque"]
