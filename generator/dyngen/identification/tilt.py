"""Torque columns of a small base tilt: the change of the gravity torques when the gravity vector
gains a horizontal component dg = (dg_x, dg_y, 0) [m/s^2] in the base frame,

    d tau_j = - z_j . sum_{i >= j} (p_ci - o_j) x (m_i dg)      (revolute joint j; prismatic: - z_j . sum m_i dg)

with z_j, o_j joint j's axis and origin and p_ci link i's centre of mass, all in the base frame.
It is linear in dg for given link parameters; the identification evaluates it with the prior's
parameters, so dg enters linearly (the error is of order dg times the parameter change).
The kinematics are the export's (DH placements), independent of the generated C.
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
    for k, e in enumerate(directions):
        for j, joint in enumerate(robot.joints):
            total = np.zeros((T, 3)) if joint.revolute else np.zeros(T)
            for i in range(j, n):
                force = links[i, 0] * e
                if joint.revolute:
                    total += np.cross(coms[i] - origins[j], force)
                else:
                    total += axes[j] @ force
            out[:, j, k] = -(np.einsum("tk,tk->t", axes[j], total) if joint.revolute else total)
    return out
