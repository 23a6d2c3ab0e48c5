"""A tilted base: the change of the gravity torques when the base is rotated, so that the gravity
vector g (the YAML's) becomes g + dg in the base frame. The gravity torque is linear in the
gravity vector, so

    d tau_j = - z_j . sum_{i >= j} (p_ci - o_j) x (m_i dg)      (revolute joint j; prismatic: - z_j . sum m_i dg)

with z_j, o_j joint j's axis and origin and p_ci link i's centre of mass, all in the base frame
(tilt_columns: these torques for given directions of dg). A rotation gives gravity components
a = (a1, a2) across it (along u1, u2, the base x and y for gravity along -z) and shortens it
along itself by |g| - sqrt(|g|^2 - |a|^2), so its size is kept (change); the identification fits
a with that shortening linearised at its previous estimate (rotation_columns), with the prior's
link parameters (identification/consistent.py says why). A tilt above MAX_TILT_DEG is no
mounting error. The kinematics are the export's (DH placements), independent of the generated C.
"""

from __future__ import annotations

import numpy as np

from ..export.frames import placements
from ..parameters import PER_LINK


def tilt_columns(robot, p, q, directions=None) -> np.ndarray:
    """(T, N, 2): d tau / d dg_x and d tau / d dg_y at the positions q (T, N), parameters p (10N)
    (other gravity directions: `directions`, rows of unit vectors)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    T, n = q.shape
    links = np.asarray(p, dtype=float).reshape(n, PER_LINK)
    places = placements(robot)
    frame = np.broadcast_to(np.eye(4), (T, 4, 4)).copy()
    axes, origins, coms = [], [], []
    for i, (joint, place) in enumerate(zip(robot.joints, places)):
        frame = frame @ place.origin
        axes.append(frame[:, :3, 2].copy())
        origins.append(frame[:, :3, 3].copy())
        J = np.broadcast_to(np.eye(4), (T, 4, 4)).copy()
        if joint.revolute:
            c, s = np.cos(q[:, i]), np.sin(q[:, i])
            J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1] = c, -s, s, c
        else:
            J[:, 2, 3] = q[:, i]
        frame = frame @ J
        dh = frame @ place.post
        coms.append(dh[:, :3, :3] @ links[i, 1:4] + dh[:, :3, 3])
    directions = np.eye(3)[:2] if directions is None else np.atleast_2d(directions)
    out = np.zeros((T, n, len(directions)))
    # sum_{i >= j} (p_ci - o_j) x (m_i e) = (S_j - M_j o_j) x e, S_j = sum_{i >= j} m_i p_ci, M_j = sum m_i
    S, M = np.zeros((T, 3)), 0.0
    for j in reversed(range(n)):
        S, M = S + links[j, 0] * coms[j], M + links[j, 0]
        if robot.joints[j].revolute:  # -z . (a x e) = -e . (z x a)
            out[:, j, :] = -np.cross(axes[j], S - M * origins[j]) @ directions.T
        else:
            out[:, j, :] = -M * (axes[j] @ directions.T)
    return out


MAX_TILT_DEG = 10.0  # a larger tilt is no mounting error (as the diagnosis's, diagnosis/effects/tilt.py)


def gravity_of(robot) -> np.ndarray | None:
    """The YAML's gravity vector, or None where it has symbols (no tilt can be fitted then)."""
    try:
        g = np.array([float(x) for x in robot.gravity])
    except (TypeError, ValueError):
        return None
    return g if np.linalg.norm(g) > 0 else None


def directions(g) -> np.ndarray:
    """(3, 3): rows u1, u2 perpendicular to gravity and n along it; for gravity along -z, u1 and
    u2 are the base x and y axes."""
    n = g / np.linalg.norm(g)
    seed = np.eye(3)[int(np.argmin(np.abs(n)))]
    u1 = seed - (seed @ n) * n
    u1 /= np.linalg.norm(u1)
    return np.array([u1, np.cross(u1, n), n])


def change(g, a) -> np.ndarray:
    """The change of the gravity vector g when the base is rotated so that gravity gains the
    components a = (a1, a2) along u1, u2: a rotation, so |g| is kept and the component along
    gravity shortens by |g| - sqrt(|g|^2 - |a|^2) (coefficients along u1, u2, n)."""
    size = float(np.linalg.norm(g))
    a = np.asarray(a, dtype=float)
    return np.array([a[0], a[1], np.sqrt(max(size ** 2 - float(a @ a), 0.0)) - size])


def angle_deg(g, a) -> float:
    """The tilt angle [deg] of the rotation that gives gravity the components a across it."""
    return float(np.degrees(np.arcsin(min(np.hypot(*a) / np.linalg.norm(g), 1.0))))


def rotation_columns(robot, p, q, g, a0=(0.0, 0.0)) -> np.ndarray:
    """(T, N, 2): the torques of the components a1, a2 of gravity across it, with the shortening
    along it that keeps |g| linearised at a0 (d tau = G u_k a_k - G n a0_k a_k / (2 |g|)): at a0 = 0
    the first-order tilt; refitted at the estimate, a rotation (the diagnosis's Tilt does the same)."""
    D = directions(g)
    G = tilt_columns(robot, p, q, D)  # (T, N, 3): the torques of unit gravity along u1, u2, n
    size = float(np.linalg.norm(g))
    return np.stack([G[..., 0] - G[..., 2] * a0[0] / (2 * size), G[..., 1] - G[..., 2] * a0[1] / (2 * size)], axis=-1)


def torque(robot, p, q, g, a) -> np.ndarray:
    """(T, N): the exact torque change of the rotation (linear in the gravity vector)."""
    return tilt_columns(robot, p, q, directions(g)) @ change(g, a)
