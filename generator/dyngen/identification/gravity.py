"""The tilt's G(q) (terms/tilt.py gravity_matrix) from the compiled model's link poses: the
forward kinematics in C, not in Python (the slowest part of a block on the first pass).

Joint i turns about z_i through o_i and carries links k >= i (mass m_k, centre c_k):
    G_i = - sum_k m_k z_i x (c_k - o_i) = - z_i x (S_i - M_i o_i),  S_i = sum_k m_k c_k,  M_i = sum_k m_k
(prismatic: - M_i z_i): one cross product per joint, not one per joint and link. Link frame i is
joint i's frame times the constant `frame` (R_f, p_f): joint i's rotation is R_link R_f^T, its
origin o_link - R_joint p_f. Equal to gravity_matrix to rounding (tests/test_consistent_identification.py)."""

from __future__ import annotations

import numpy as np

from ..description.joint_model import _constant
from ..terms import tilt


def gravity_matrix_of(model, robot, p):
    """q (T, N) -> G (T, N, 3) for dynamic link parameters p (10N): compiled when the model has
    link_poses, else terms.tilt.gravity_matrix."""
    if f"{model.prefix}_link_poses" not in model.functions:
        return lambda q: tilt.gravity_matrix(robot, p, q)
    links = np.asarray(p, dtype=float).reshape(-1, 10)
    joints = robot.joint_models
    # D_i = S_i - M_i o_i and z_i are linear in the link poses [R p] (3 x 4 each): one (3T, 4N) @
    # (4N, 2N) product gives them all; W's rows: link k's homogeneous points (w = 1) and directions (w = 0)
    n, m = len(robot.joint_models), links[:, 0]
    after = np.cumsum(m[::-1])[::-1]  # M_i
    W = np.zeros((n, 4, 2, n))
    for i, joint in enumerate(robot.joint_models):
        turn, shift = _constant(joint.frame.R).T, _constant(joint.frame.p)[:, 0]  # joint i in link frame i
        for k in range(i, n):
            W[k, :, 0, i] += m[k] * np.r_[links[k, 1:4], 1.0]  # m_k c_k
        W[i, :, 0, i] -= after[i] * np.r_[-turn @ shift, 1.0]  # M_i o_i
        W[i, :, 1, i] = np.r_[turn[:, 2], 0.0]  # z_i
    W = W.reshape(4 * n, 2 * n)
    prismatic = [i for i, joint in enumerate(robot.joint_models) if not joint.revolute]

    def G(q):
        T = q.shape[0]
        poses = model.batch("link_poses", q).reshape(T, n, 4, 4)[:, :, :3, :]
        X = (poses.transpose(0, 2, 1, 3).reshape(3 * T, 4 * n) @ W).reshape(T, 3, 2, n)
        (dx, dy, dz), (zx, zy, zz) = X[:, :, 0].transpose(1, 0, 2), X[:, :, 1].transpose(1, 0, 2)
        out = np.stack([zz * dy - zy * dz, zx * dz - zz * dx, zy * dx - zx * dy], axis=-1)  # -z x D
        for i in prismatic:
            out[:, i] = -after[i] * X[:, :, 1, i]
        return out

    return G
