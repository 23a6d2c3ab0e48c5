"""A tilted base, and a gravity of the wrong size, as candidates of the diagnosis (the terms,
G(q) and the directions: terms/tilt.py).

tilt: the residual is G(q) d gvec across gravity (dg1, dg2), with the shortening along gravity
  that keeps |gvec| linearised at the current estimate, refined by fixed-point iteration once
  the tilt is selected (refine.py). The angles are named by the base axes they turn gravity
  towards (tilt_axes). Tilts beyond terms.tilt.MAX_TILT_DEG are not a mounting error and are refused.
gravity_scale: always reported as suspect (a symptom, not a cause).
"""

from __future__ import annotations

import numpy as np

from ... import terms
from ...description.joint_model import forward_kinematics
from ...terms.tilt import (body_gravity_matrix, gravity_matrix, gravity_norm, tilt_angles_deg, tilt_axes,
                           tilt_directions)
from .base import Effect


class Tilt(Effect):
    term = terms.Tilt
    refinable = True

    def __init__(self, g: float, directions, estimate=(0.0, 0.0)):
        self.g = float(g)  # |gravity| of the robot's model
        self.directions = directions  # (u1, u2): tilt_directions of the robot
        self.estimate = tuple(float(x) for x in estimate)  # dg1, dg2 of the second-order term
        self.label = "" if not any(self.estimate) else f"dg0=({self.estimate[0]:.6g},{self.estimate[1]:.6g})"

    @classmethod
    def of(cls, context):
        return cls(gravity_norm(context.robot), tilt_directions(context.robot))

    @property
    def setting(self):
        return np.array(self.estimate)

    def implied_setting(self, values):
        return np.array(values[:2], dtype=float) if np.any(values[:2]) else None

    def at(self, setting):
        return Tilt(self.g, self.directions, setting)

    def reads(self, context):
        return (context.load,)

    def columns(self, context, signals, tau_model):
        return self.term.columns(_gravity(context, signals), *self.directions, self.g, self.estimate)

    def range_scales(self):
        return {"g": self.g}

    def derived(self, robot, values, std, torque_rms):
        if None in values.values():
            return {}
        a1, a2 = tilt_angles_deg(robot, [values["dg1"], values["dg2"]])
        s1, s2 = tilt_angles_deg(robot, [std["dg1"], std["dg2"]])
        return {"tilt_deg": [a1, a2], "tilt_std_deg": [abs(s1), abs(s2)], "tilt_towards": list(tilt_axes(robot)),
                "tilt_total_deg": float(np.hypot(a1, a2))}


class GravityScale(Effect):
    term = terms.GravityScale
    suspect = ("no tilt changes gravity's size; every link's gravity torque scaled alike points at masses and "
               "centres of mass wrong by one factor, or at a torque-sensor gain")
    secondary = True

    def __init__(self, g: float):
        self.g = float(g)  # |gravity| of the robot's model

    @classmethod
    def of(cls, context):
        return cls(gravity_norm(context.robot))

    def reads(self, context):
        return (context.load,)

    def columns(self, context, signals, tau_model):
        return self.term.columns(_gravity(context, signals), *tilt_directions(context.robot))

    def range_scales(self):
        return {"g": self.g}

    def derived(self, robot, values, std, torque_rms):
        return {} if values.get("dg") is None else {"relative": values["dg"] / self.g}


def _gravity(context, signals) -> np.ndarray:
    """G(q) of a recording, computed once for the tilt and the gravity scale, with a chosen
    payload (Context.load) on the last link: a tilt turns its gravity too."""
    G = context.memo(("gravity_matrix", id(signals)),
                     lambda: gravity_matrix(context.robot, context.p, signals.q, _poses(context, signals)))
    if context.load is None:
        return G
    return G + body_gravity(context, signals) @ np.asarray(context.load)


def body_gravity(context, signals) -> np.ndarray:
    """B (T, N, 3, 4) of a recording: a body on the last link with standard values (m, mx,
    my, mz) in its frame adds sum_k B[..., k] value_k to G(q) (docs: gravity_matrix)."""
    return context.memo(("body_gravity", id(signals)),
                        lambda: body_gravity_matrix(context.robot, signals.q, _poses(context, signals)))


def _poses(context, signals):
    return context.memo(("poses", id(signals)), lambda: forward_kinematics(context.robot.joint_models, signals.q))


