"""A tilted base: gravity in the base frame is not the model's direction.

The gravity torque is linear in the gravity vector: g(q) = G(q) gvec, with column k of G the
joint torques that a unit gravity along base axis k would cause. A tilt by small angles turns
gvec by d gvec, perpendicular to it, so the residual is G(q) d gvec: three columns, G(q) u1, G(q) u2 and
G(q) n, with u1, u2 unit vectors perpendicular to the model's gravity and n along it. The
fitted values are the components of d gvec [m/s^2]; the third takes the second-order change
along gravity (|gvec| (1 - cos angle)), so the tilt is exact, not only to first order. The
tilt angles follow from the rotated vector gvec + d gvec.

G(q) comes from the joint models' forward kinematics (numpy, vectorised over samples):
for joint i with axis z through o, and every link k it carries, with centre of mass p_k,
  revolute:  G_i = - sum_k m_k (z x (p_k - o))      prismatic:  G_i = - sum_k m_k z
(the potential is V = -sum m_k gvec . p_k and g = dV/dq).
"""

from __future__ import annotations

import numpy as np

from ...description.joint_model import forward_kinematics
from .base import Effect


class Tilt(Effect):
    name, scope = "tilt", "arm"
    parameters = ("dg1", "dg2", "dgn")
    units = ("m/s^2", "m/s^2", "m/s^2")

    def columns(self, context, signals, tau_model):
        G = gravity_matrix(context.robot, context.p, signals.q)  # (T, N, 3)
        u1, u2 = tilt_directions(context.robot)
        n = np.cross(u1, u2)
        return np.stack([G @ u1, G @ u2, G @ n], axis=-1)


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
    dg2, dgn): the angles of the rotated vector's u1 and u2 components against its component
    along the model's gravity."""
    g = np.linalg.norm([float(x) for x in robot.gravity])
    along = g + dg[2]
    return float(np.degrees(np.arctan2(dg[0], along))), float(np.degrees(np.arctan2(dg[1], along)))


def gravity_matrix(robot, p, q) -> np.ndarray:
    """G (T, N, 3) with g(q) = G(q) gvec for link parameters p (dynamic, 10N)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    links = np.asarray(p, dtype=float).reshape(-1, 10)
    poses = forward_kinematics(robot.joint_models, q)
    n = len(poses)
    G = np.zeros((q.shape[0], n, 3))
    centres = [pose.origin + np.einsum("tij,j->ti", pose.R, links[k, 1:4]) for k, pose in enumerate(poses)]
    for i, model in enumerate(robot.joint_models):
        z, o = poses[i].axis, poses[i].point
        for k in range(i, n):
            m = links[k, 0]
            G[:, i, :] -= m * (np.cross(z, centres[k] - o) if model.revolute else z)
    return G
