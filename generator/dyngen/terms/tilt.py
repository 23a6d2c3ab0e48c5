"""A tilted base and a gravity of the wrong size, from the joint model's forward kinematics.

g(q) = G(q) gvec: for joint i (axis z through o) and every link k it carries (mass m_k, centre p_k)
    revolute:  G_i = - sum_k m_k (z x (p_k - o))      prismatic:  G_i = - sum_k m_k z
tilt: the base turns gvec by dg1 u1 + dg2 u2 across gravity (`directions`) and shortens it along n
  by -(dg1^2 + dg2^2) / (2 |g|), so its size is kept: column k is G u_k - G n dg_k0 / (2 |g|),
  linearised at an estimate dg_k0 and refitted. Beyond MAX_TILT_DEG it is no mounting error.
gravity_scale: G n dg (no tilt does this: reported as suspect)."""

from __future__ import annotations

import numpy as np

from ..description.joint_model import forward_kinematics
from .term import Term, Value

MAX_TILT_DEG = 10.0  # a larger tilt is no mounting error
MAX_GRAVITY_SCALE = 0.1  # relative: a larger change of gravity's size is no tilt's nor a model's rounding


def gravity_of(robot) -> np.ndarray | None:
    """The YAML's gravity vector, or None where it has symbols or is zero (no tilt then)."""
    try:
        g = np.array([float(x) for x in robot.gravity])
    except (TypeError, ValueError):
        return None
    return g if np.linalg.norm(g) > 0 else None


def gravity_norm(robot) -> float:
    return float(np.linalg.norm([float(x) for x in robot.gravity]))


def directions(g) -> np.ndarray:
    """(3, 3): rows u1, u2 across gravity and n along it, u2 = n x u1 (for gravity along -z: +x, -y, -z)."""
    g = np.asarray(g, dtype=float)
    n = g / np.linalg.norm(g)
    seed = np.eye(3)[int(np.argmin(np.abs(n)))]
    u1 = seed - (seed @ n) * n
    u1 /= np.linalg.norm(u1)
    return np.array([u1, np.cross(n, u1), n])


def tilt_directions(robot) -> tuple[np.ndarray, np.ndarray]:
    return tuple(directions([float(x) for x in robot.gravity])[:2])


def tilt_axes(robot) -> tuple[str, str]:
    """Names of u1 and u2 in the base frame, e.g. ("base +x", "base -y")."""
    names = []
    for u in tilt_directions(robot):
        k = int(np.argmax(np.abs(u)))
        names.append(f"base {'+' if u[k] > 0 else '-'}{'xyz'[k]}" if abs(abs(u[k]) - 1.0) < 1e-9
                     else "base (" + ", ".join(f"{x:.3g}" for x in u) + ")")
    return names[0], names[1]


def angle_deg(g, a) -> float:
    """The tilt angle [deg] giving gravity g the components a across it, |a| = |g| sin(angle): the one formula."""
    return float(np.degrees(np.arcsin(min(np.hypot(*a[:2]) / np.linalg.norm(g), 1.0))))


def angles_deg(g, a) -> tuple[float, float]:
    """The tilt angle split along u1, u2 (angle_deg times a / |a|)."""
    size = float(np.hypot(*a[:2]))
    if size == 0.0:
        return 0.0, 0.0
    angle = angle_deg(g, a)
    return angle * float(a[0]) / size, angle * float(a[1]) / size


def change(g, a) -> np.ndarray:
    """The change of g (along u1, u2, n) when gravity gains the components a across it (|g| kept)."""
    size = float(np.linalg.norm(g))
    a = np.asarray(a, dtype=float)
    return np.array([a[0], a[1], np.sqrt(max(size ** 2 - float(a @ a), 0.0)) - size])


def gravity_matrix(robot, p, q, poses=None) -> np.ndarray:
    """G (T, N, 3) with g(q) = G(q) gvec for dynamic link parameters p (10N); poses: q's kinematics."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    links = np.asarray(p, dtype=float).reshape(-1, 10)
    poses = poses or forward_kinematics(robot.joint_models, q)
    n = len(poses)
    # component-major (3, N, T), each component a contiguous row: the cross products written out as
    # np.cross computes them (a1 b2 - a2 b1, ...), the same operations in the same order, so G is
    # bitwise the same, in 2/5 of the time (np.cross on (T, 3) arrays: strided and a dozen calls)
    G = np.zeros((3, n, q.shape[0]))
    centres = [(pose.origin + np.einsum("tij,j->ti", pose.R, links[k, 1:4])).T.copy() for k, pose in enumerate(poses)]
    for i, model in enumerate(robot.joint_models):
        z, o = poses[i].axis.T.copy(), poses[i].point.T.copy()
        for k in range(i, n):
            m = links[k, 0]
            if not model.revolute:
                G[:, i] -= m * z
                continue
            d = centres[k] - o
            G[0, i] -= m * (z[1] * d[2] - z[2] * d[1])
            G[1, i] -= m * (z[2] * d[0] - z[0] * d[2])
            G[2, i] -= m * (z[0] * d[1] - z[1] * d[0])
    return np.ascontiguousarray(G.transpose(2, 1, 0))


def body_gravity_matrix(robot, poses) -> np.ndarray:
    """B (T, N, 3, 4): G(q) of a body on the last link per unit of (m, mx, my, mz): -z x (o_N - o), -z x R_N e_k
    (poses: q's kinematics)."""
    last = poses[-1]
    B = np.zeros((last.origin.shape[0], len(poses), 3, 4))
    for i, model in enumerate(robot.joint_models):
        z, o = poses[i].axis, poses[i].point
        if model.revolute:
            B[:, i, :, 0] = -np.cross(z, last.origin - o)
            for k in range(3):
                B[:, i, :, 1 + k] = -np.cross(z, last.R[:, :, k])
        else:
            B[:, i, :, 0] = -z
    return B


class _Gravity(Term):
    """A term of the recording's gravity torques G(q) (recording_gravity), ranged relative to |g|."""

    scope = "arm"

    def reads(self, context):
        return (context.load,)

    def range_scales(self):
        return {"g": self.g}


class Tilt(_Gravity):
    """As a candidate it is linearised at the current estimate, refined once selected (refine.py)."""

    name, doc = "tilt", "a tilted base: gravity turned by dg1 u1 + dg2 u2, its size kept"
    values = (Value("dg1", "m/s^2"), Value("dg2", "m/s^2"))
    refinable = True

    def __init__(self, g: float, directions, estimate=(0.0, 0.0)):
        self.g = float(g)  # |gravity| of the robot's model
        self.directions = directions  # (u1, u2): tilt_directions of the robot
        self.estimate = tuple(float(x) for x in estimate)  # dg1, dg2 of the second-order term
        self.label = "" if not any(self.estimate) else f"dg0=({self.estimate[0]:.6g},{self.estimate[1]:.6g})"

    @classmethod
    def inside(cls, values, scales=None):
        return angle_deg(scales["g"], values) < MAX_TILT_DEG

    @staticmethod
    def regressor(G, u1, u2, g: float, estimate=(0.0, 0.0)):
        """(T, N, 2) from G (T, N, 3), linearised at the estimate (dg1, dg2)."""
        along = G @ np.cross(u1, u2)
        return np.stack([G @ u1 - along * estimate[0] / (2 * g), G @ u2 - along * estimate[1] / (2 * g)], axis=-1)

    @classmethod
    def of(cls, context):
        return cls(gravity_norm(context.robot), tilt_directions(context.robot))

    def columns(self, context, signals, tau_model):
        return self.regressor(recording_gravity(context, signals), *self.directions, self.g, self.estimate)

    @property
    def setting(self):
        return np.array(self.estimate)

    def implied_setting(self, values):
        return np.array(values[:2], dtype=float) if np.any(values[:2]) else None

    def at(self, setting):
        return Tilt(self.g, self.directions, setting)

    def derived(self, robot, values, std, torque_rms):
        if None in values.values():
            return {}
        a = [values["dg1"], values["dg2"]]
        # a std's angle: that of a tilt of one std along each direction alone
        s1, s2 = angle_deg(self.g, [std["dg1"], 0.0]), angle_deg(self.g, [0.0, std["dg2"]])
        return {"tilt_deg": list(angles_deg(self.g, a)), "tilt_std_deg": [s1, s2], "tilt_towards": list(tilt_axes(robot)),
                "tilt_total_deg": angle_deg(self.g, a)}


class GravityScale(_Gravity):
    name, doc = "gravity_scale", "gravity's size changed by dg: every link's gravity torque scaled alike"
    values = (Value("dg", "m/s^2", -MAX_GRAVITY_SCALE, MAX_GRAVITY_SCALE, per="g"),)
    suspect = ("no tilt changes gravity's size; every link's gravity torque scaled alike points at masses and "
               "centres of mass wrong by one factor, or at a torque-sensor gain")
    secondary = True

    def __init__(self, g: float):
        self.g = float(g)  # |gravity| of the robot's model

    @staticmethod
    def regressor(G, u1, u2):
        return (G @ np.cross(u1, u2))[:, :, None]

    @classmethod
    def of(cls, context):
        return cls(gravity_norm(context.robot))

    def columns(self, context, signals, tau_model):
        return self.regressor(recording_gravity(context, signals), *tilt_directions(context.robot))

    def derived(self, robot, values, std, torque_rms):
        return {} if values.get("dg") is None else {"relative": values["dg"] / self.g}


def recording_gravity(context, signals) -> np.ndarray:
    """G(q) of a recording (memoised), with a chosen payload on the last link (Context.load)."""
    def poses():
        return context.memo(("poses", id(signals)), lambda: forward_kinematics(context.robot.joint_models, signals.q))

    G = context.memo(("gravity_matrix", id(signals)), lambda: gravity_matrix(context.robot, context.p, signals.q, poses()))
    if context.load is None:
        return G
    B = context.memo(("body_gravity", id(signals)), lambda: body_gravity_matrix(context.robot, poses()))
    return G + B @ np.asarray(context.load)


def torque(robot, p, q, g, a) -> np.ndarray:
    """(T, N): the exact torque change of the rotation (linear in the gravity vector)."""
    return gravity_matrix(robot, p, q) @ (directions(g).T @ change(g, a))
