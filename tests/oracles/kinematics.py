"""Kinematics oracles, independent of dyngen: numpy forward kinematics with numerical
derivatives, and Pinocchio's frames, Jacobians and classical accelerations.

numpy: the DH transforms of oracles/lagrangian.py (complex-safe), the tool read from the YAML
by the oracles' own evaluator, J by complex-step differentiation of FK (exact to rounding:
no subtraction), Jdot qd by Richardson-extrapolated central differences of that J along qd.
"""
from __future__ import annotations

import numpy as np
import pinocchio as pin
import yaml

from . import lagrangian as lag
from . import pinocchio_arm as pin_arm
from .arm import Arm, evaluate


def tool_matrix(path) -> np.ndarray:
    """The YAML's `tool:` (xyz, rpy in the last link frame) as 4x4: Trans(xyz) Rz(y) Ry(p) Rx(r)."""
    with open(path, encoding="utf-8") as f:
        tool = yaml.safe_load(f).get("tool") or {}
    x, y, z = (evaluate(v) for v in tool.get("xyz", [0, 0, 0]))
    r, p, w = (evaluate(v) for v in tool.get("rpy", [0, 0, 0]))
    Rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    Ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    Rz = np.array([[np.cos(w), -np.sin(w), 0], [np.sin(w), np.cos(w), 0], [0, 0, 1]])
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = Rz @ Ry @ Rx, [x, y, z]
    return T


def poses(arm: Arm, tool: np.ndarray, q) -> list:
    """[T_1, ..., T_N, T_flange] in the base frame (complex q allowed)."""
    frames = lag.forward_kinematics(arm, q)[1:]
    return frames + [frames[-1] @ tool]


def _complex_step_jacobian(pose_of_q, q, h=1e-30) -> np.ndarray:
    """6 x N [v; w] of a pose function: d o / dq_k and the axial vector of (dR/dq_k) R^T."""
    q = np.asarray(q, dtype=float)
    T = pose_of_q(q.astype(complex)).real
    J = np.zeros((6, q.size))
    for k in range(q.size):
        dq = q.astype(complex)
        dq[k] += 1j * h
        dT = pose_of_q(dq).imag / h
        W = dT[:3, :3] @ T[:3, :3].T
        J[:3, k] = dT[:3, 3]
        J[3:, k] = [W[2, 1], W[0, 2], W[1, 0]]
    return J


def jacobian(arm: Arm, tool, q, link: int | None = None) -> np.ndarray:
    """Of the flange (link None) or of link frame `link` (1-based)."""
    index = -1 if link is None else link - 1
    return _complex_step_jacobian(lambda x: poses(arm, tool, x)[index], q)


def jacobian_dot_qd(arm: Arm, tool, q, qd, h=1e-3) -> np.ndarray:
    """d/dt J(q + t qd) at t = 0, times qd: central differences at h and h/2, Richardson (O(h^4))."""
    q, qd = np.asarray(q, float), np.asarray(qd, float)

    def central(step):
        return (jacobian(arm, tool, q + step * qd) - jacobian(arm, tool, q - step * qd)) / (2 * step)

    return ((4 * central(h / 2) - central(h)) / 3) @ qd


# --- Pinocchio -----------------------------------------------------------------------

def pinocchio_model(arm: Arm, tool: np.ndarray):
    """The oracles' Pinocchio model with a "tool" frame on the last joint: post_N * tool."""
    model, _ = pin_arm.build(arm)
    _, post = pin_arm.split_joint(arm.convention, arm.joints[-1])
    placement = post @ tool
    model.addFrame(pin.Frame("tool", model.njoints - 1, pin.SE3(placement[:3, :3], placement[:3, 3]),
                             pin.FrameType.OP_FRAME))
    return model, model.createData()


def pinocchio_kinematics(model, data, n: int, q, qd) -> dict:
    """poses (N link frames + tool), Jacobians [v; w] in LOCAL_WORLD_ALIGNED, tool's Jdot qd."""
    frames = [model.getFrameId(f"frame{i + 1}") for i in range(n)] + [model.getFrameId("tool")]
    q, qd = np.asarray(q, float), np.asarray(qd, float)
    pin.forwardKinematics(model, data, q, qd, np.zeros(n))
    pin.updateFramePlacements(model, data)
    pin.computeJointJacobians(model, data, q)
    world = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    out = {"poses": [data.oMf[f].homogeneous.copy() for f in frames],
           "jacobians": [pin.getFrameJacobian(model, data, f, world).copy() for f in frames]}
    pin.forwardKinematics(model, data, q, qd, np.zeros(n))  # computeJointJacobians reset velocities
    acc = pin.getFrameClassicalAcceleration(model, data, frames[-1], world)
    out["jdot_qd"] = np.concatenate([acc.linear, acc.angular])
    return out
