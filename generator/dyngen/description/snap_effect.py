"""What each snap changes: the largest change of the gravity torques it causes over random joint
positions (the arm read with that one constant kept as written, against the snapped arm).

Gravity torques, because they need only the link poses (joint_model.forward_kinematics) and
are the largest static share of the torques; tau_i = -sum over links k >= i of m_k g . (z_i x
(c_k - o_i)) for a revolute joint i (z_i its axis, o_i a point on it), -sum m_k g . z_i for a
prismatic one.
"""

from __future__ import annotations

import numpy as np

from .joint_model import forward_kinematics

STATES = 200


def gravity_torques(robot, q) -> np.ndarray:
    poses = forward_kinematics(robot.joint_models, q)
    g = np.array([float(x) for x in robot.gravity])
    weights = [(v.m, pose.origin + np.einsum("tij,j->ti", pose.R, np.asarray(v.c))) for v, pose in
               zip(robot.nominal, poses)]
    tau = np.zeros(q.shape)
    for i, (pose, model) in enumerate(zip(poses, robot.joint_models)):
        for m, com in weights[i:]:
            arm = np.cross(pose.axis, com - pose.point) if model.revolute else pose.axis
            tau[:, i] -= m * arm @ g
    return tau


def snap_effects(robot, load) -> tuple:
    """Per snap of robot: the largest |change| of a gravity torque [N m or N]; load(keep) reads
    the same file with the (joint, field) pairs in keep left as written."""
    if robot.gravity_symbols:
        return tuple(None for _ in robot.snaps)
    rng = np.random.default_rng(0)
    q = rng.uniform(-np.pi, np.pi, (STATES, robot.dof))
    base = gravity_torques(robot, q)
    return tuple(float(np.max(np.abs(gravity_torques(load(frozenset({(x.joint, x.field)})), q) - base)))
                 for x in robot.snaps)
