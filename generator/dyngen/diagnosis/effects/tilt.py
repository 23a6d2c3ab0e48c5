"""A tilted base, and a gravity of the wrong size.

The gravity torque is linear in the gravity vector: g(q) = G(q) gvec, with column k of G the
joint torques that a unit gravity along base axis k would cause.

tilt: a rotation of the base turns gvec by d gvec, so the residual is G(q) d gvec. Across
  gravity, d gvec = dg1 u1 + dg2 u2 (u1, u2 unit vectors perpendicular to the model's gravity):
  two fitted values. Along gravity a rotation shortens the component by exactly what keeps
  |gvec| unchanged, -(dg1^2 + dg2^2) / (2 |g|) to second order (0.013 m/s^2 for 3 deg: small,
  but a diagnosis that left it out would report it as a gravity scale). It is not a third
  value: column k is G u_k - G n dg_k0 / (2 |g|) at the current estimate dg_k0, refined by
  fixed-point iteration once the tilt is selected (refine.py), so a tilt cannot change
  gravity's magnitude. The angles follow from the rotated vector, and are named by the
  base axes they turn gravity towards (tilt_axes). Tilts beyond MAX_TILT_DEG are not a
  mounting error and are refused.
gravity_scale: G(q) n dg, n along gravity: the gravity torque of every link scaled alike. No
  tilt does this; masses and centres of mass all wrong by one factor, or a torque gain, do.
  It is always reported as suspect (a symptom, not a cause).

G(q) comes from the joint models' forward kinematics (numpy, vectorised over samples):
for joint i with axis z through o, and every link k it carries, with centre of mass p_k,
  revolute:  G_i = - sum_k m_k (z x (p_k - o))      prismatic:  G_i = - sum_k m_k z
(the potential is V = -sum m_k gvec . p_k and g = dV/dq).
"""

from __future__ import annotations

import numpy as np

from ...description.joint_model import forward_kinematics
from .base import Effect


MAX_TILT_DEG = 10.0
MAX_GRAVITY_SCALE = 0.1  # relative: a larger change of gravity's size is refused


def gravity_norm(robot) -> float:
    return float(np.linalg.norm([float(x) for x in robot.gravity]))


class Tilt(Effect):
    name, scope = "tilt", "arm"
    parameters = ("dg1", "dg2")
    units = ("m/s^2", "m/s^2")
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
        G = _gravity(context, signals)  # (T, N, 3)
        u1, u2 = self.directions
        along = G @ np.cross(u1, u2)
        return np.stack([G @ u1 - along * self.estimate[0] / (2 * self.g),
                         G @ u2 - along * self.estimate[1] / (2 * self.g)], axis=-1)

    def plausible(self, values):
        return bool(np.hypot(*values[:2]) < self.g * np.sin(np.radians(MAX_TILT_DEG)))

    def derived(self, robot, values, std, torque_rms):
        if None in values.values():
            return {}
        a1, a2 = tilt_angles_deg(robot, [values["dg1"], values["dg2"]])
        s1, s2 = tilt_angles_deg(robot, [std["dg1"], std["dg2"]])
        return {"tilt_deg": [a1, a2], "tilt_std_deg": [abs(s1), abs(s2)], "tilt_towards": list(tilt_axes(robot)),
                "tilt_total_deg": float(np.hypot(a1, a2))}


class GravityScale(Effect):
    name, scope = "gravity_scale", "arm"
    parameters = ("dg",)
    units = ("m/s^2",)
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
        G = _gravity(context, signals)
        u1, u2 = tilt_directions(context.robot)
        return (G @ np.cross(u1, u2))[:, :, None]

    def plausible(self, values):
        return bool(abs(values[0]) < MAX_GRAVITY_SCALE * self.g)

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


def tilt_directions(robot) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors perpendicular to the model's gravity (the base x or y axis made
    perpendicular; for gravity along -z they are x and -y)."""
    g = np.array([float(x) for x in robot.gravity])
    n = g / np.linalg.norm(g)
    seed = np.eye(3)[int(np.argmin(np.abs(n)))]
    u1 = seed - (seed @ n) * n
    u1 /= np.linalg.norm(u1)
    return u1, np.cross(n, u1)


def tilt_angles_deg(robot, dg) -> tuple[float, float]:
    """Rotation angles [deg] of gravity towards u1 and u2 for the fitted components (dg1,
    dg2): the angles of the rotated vector's u1 and u2 components against gravity."""
    g = np.linalg.norm([float(x) for x in robot.gravity])
    return float(np.degrees(np.arctan2(dg[0], g))), float(np.degrees(np.arctan2(dg[1], g)))


def tilt_axes(robot) -> tuple[str, str]:
    """Names of u1 and u2 in the base frame, e.g. ("base +x", "base -y") for gravity along -z."""
    names = []
    for u in tilt_directions(robot):
        k = int(np.argmax(np.abs(u)))
        if abs(abs(u[k]) - 1.0) < 1e-9:
            names.append(f"base {'+' if u[k] > 0 else '-'}{'xyz'[k]}")
        else:
            names.append("base (" + ", ".join(f"{x:.3g}" for x in u) + ")")
    return names[0], names[1]


def gravity_matrix(robot, p, q, poses=None) -> np.ndarray:
    """G (T, N, 3) with g(q) = G(q) gvec for link parameters p (dynamic, 10N); poses: the
    forward kinematics of q, if computed already."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    links = np.asarray(p, dtype=float).reshape(-1, 10)
    poses = poses or forward_kinematics(robot.joint_models, q)
    n = len(poses)
    G = np.zeros((q.shape[0], n, 3))
    centres = [pose.origin + np.einsum("tij,j->ti", pose.R, links[k, 1:4]) for k, pose in enumerate(poses)]
    for i, model in enumerate(robot.joint_models):
        z, o = poses[i].axis, poses[i].point
        for k in range(i, n):
            m = links[k, 0]
            G[:, i, :] -= m * (np.cross(z, centres[k] - o) if model.revolute else z)
    return G


def body_gravity_matrix(robot, q, poses=None) -> np.ndarray:
    """B (T, N, 3, 4): the G(q) of a body on the last link per unit of its standard values
    (m, mx, my, mz; first moments in the last link's frame). Its mass times its centre is
    m o_N + R_N (mx, my, mz), so for a revolute joint i (axis z through o):
    B_i = -[z x (o_N - o), z x R_N e_x, z x R_N e_y, z x R_N e_z]; prismatic: [-z, 0, 0, 0]."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    poses = poses or forward_kinematics(robot.joint_models, q)
    last = poses[-1]
    B = np.zeros((q.shape[0], len(poses), 3, 4))
    for i, model in enumerate(robot.joint_models):
        z, o = poses[i].axis, poses[i].point
        if model.revolute:
            B[:, i, :, 0] = -np.cross(z, last.origin - o)
            for k in range(3):
                B[:, i, :, 1 + k] = -np.cross(z, last.R[:, :, k])
        else:
            B[:, i, :, 0] = -z
    return B
