"""The same Arm as a Pinocchio model: a second, independent dynamics implementation.

Every DH link transform is split as  T(i-1, i)(q) = pre_i * Joint_i(q) * post_i  where
Joint_i is a pure rotation about z (JointModelRZ) or translation along z (JointModelPZ):

  standard  revolute : Rz(theta0 + q) Tz(d) Tx(a) Rx(alpha)  -> pre = Rz(theta0),        post = Tz(d) Tx(a) Rx(alpha)
  standard  prismatic: Rz(theta) Tz(d0 + q) Tx(a) Rx(alpha)  -> pre = Rz(theta) Tz(d0),  post = Tx(a) Rx(alpha)
  modified  revolute : Rx(alpha) Tx(a) Rz(theta0 + q) Tz(d)  -> pre = Rx(alpha) Tx(a) Rz(theta0),        post = Tz(d)
  modified  prismatic: Rx(alpha) Tx(a) Rz(theta) Tz(d0 + q)  -> pre = Rx(alpha) Tx(a) Rz(theta) Tz(d0), post = I

(Rz(theta0 + q) = Rz(theta0) Rz(q), Tz(d0 + q) = Tz(d0) Tz(q).)  So the Pinocchio joint
frame J_i (after its motion) satisfies  frame_i = J_i * post_i, and the placement of
joint i in its parent joint's frame is post_{i-1} * pre_i  (post_0 = I).
Link i's inertia is given in frame i, so it enters Pinocchio as post_i.act(Y_i).
The DH frames are added as operational frames "frame1".."frameN" for FK checks.

Pinocchio's regressor parameters per body are [m, mc_x, mc_y, mc_z, I_xx, I_xy, I_yy,
I_xz, I_yz, I_zz] about the *joint frame* origin, in joint-frame axes; where the joint
frame differs from frame i (standard DH) they are not the s of docs/conventions.md.
`standard_regressor` maps them to s (frame i, conventions order).
"""
from __future__ import annotations

import numpy as np
import pinocchio as pin

from .arm import Arm


def _se3(T) -> pin.SE3:
    return pin.SE3(np.asarray(T[:3, :3], dtype=float), np.asarray(T[:3, 3], dtype=float))


def _rz(t):
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def _rx(t):
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4)
    T[1:3, 1:3] = [[c, -s], [s, c]]
    return T


def _tz(d):
    T = np.eye(4)
    T[2, 3] = d
    return T


def _tx(a):
    T = np.eye(4)
    T[0, 3] = a
    return T


def split_joint(convention: str, joint) -> tuple:
    """(pre, post) 4x4 with T(i-1, i)(q) = pre @ Joint(q) @ post (see module docstring)."""
    jtype, a, alpha, d, theta = joint
    if convention == "standard":
        if jtype == "revolute":
            return _rz(theta), _tz(d) @ _tx(a) @ _rx(alpha)
        return _rz(theta) @ _tz(d), _tx(a) @ _rx(alpha)
    if convention == "modified":
        if jtype == "revolute":
            return _rx(alpha) @ _tx(a) @ _rz(theta), _tz(d)
        return _rx(alpha) @ _tx(a) @ _rz(theta) @ _tz(d), np.eye(4)
    raise ValueError(convention)


def _link_inertia(pi) -> pin.Inertia:
    """Dynamic parameters of one link (frame i) -> pin.Inertia in frame i."""
    m, cx, cy, cz, xx, xy, xz, yy, yz, zz = pi
    Ic = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)
    return pin.Inertia(float(m), np.array([cx, cy, cz], dtype=float), Ic)


def build(arm: Arm, p=None):
    """(model, data) for the arm with dynamic parameters p (10N); p=None gives every link
    m = 1, c = 0, I = E (enough for kinematics and regressors, which do not depend on p)."""
    if p is None:
        p = np.tile([1.0, 0, 0, 0, 1.0, 0, 0, 1.0, 0, 1.0], arm.n)
    P = np.asarray(p, dtype=float).reshape(arm.n, 10)
    model = pin.Model()
    model.name = "arm"
    parent = 0
    prev_post = np.eye(4)
    for i, joint in enumerate(arm.joints):
        pre, post = split_joint(arm.convention, joint)
        jmodel = pin.JointModelRZ() if joint[0] == "revolute" else pin.JointModelPZ()
        jid = model.addJoint(parent, jmodel, _se3(prev_post @ pre), f"joint{i + 1}")
        model.appendBodyToJoint(jid, _se3(post).act(_link_inertia(P[i])), pin.SE3.Identity())
        model.addFrame(pin.Frame(f"frame{i + 1}", jid, _se3(post), pin.FrameType.OP_FRAME))
        parent, prev_post = jid, post
    model.gravity.linear = np.asarray(arm.gravity, dtype=float)
    return model, model.createData()


def _v(x):
    return np.asarray(x, dtype=float)


def rnea(arm: Arm, p, q, qd, qdd) -> np.ndarray:
    model, data = build(arm, p)
    return pin.rnea(model, data, _v(q), _v(qd), _v(qdd)).copy()


def gravity(arm: Arm, p, q) -> np.ndarray:
    model, data = build(arm, p)
    return pin.computeGeneralizedGravity(model, data, _v(q)).copy()


def mass_matrix(arm: Arm, p, q) -> np.ndarray:
    """crba (Pinocchio fills the upper triangle; symmetrised here)."""
    model, data = build(arm, p)
    M = pin.crba(model, data, _v(q)).copy()
    return np.triu(M) + np.triu(M, 1).T


def frame_poses(arm: Arm, q) -> list:
    """[T_1, ..., T_N] 4x4 poses of the DH frames in the base frame, from Pinocchio."""
    model, data = build(arm)
    pin.framesForwardKinematics(model, data, _v(q))
    return [data.oMf[model.getFrameId(f"frame{i + 1}")].homogeneous.copy() for i in range(arm.n)]


def pinocchio_parameters(model) -> np.ndarray:
    """Pinocchio's own parameter vector (10N): per body inertia.toDynamicParameters()."""
    return np.concatenate([model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)])


def joint_torque_regressor(arm: Arm, q, qd, qdd, with_gravity: bool = True) -> np.ndarray:
    """N x 10N, Pinocchio's parameter order and frames (see module docstring)."""
    model, data = build(arm)
    if not with_gravity:
        model.gravity.linear = np.zeros(3)
    return pin.computeJointTorqueRegressor(model, data, _v(q), _v(qd), _v(qdd)).copy()


# --- Pinocchio parameters (joint frame) <-> standard parameters s (frame i) ------------

def _skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def _spatial_from_standard(si) -> np.ndarray:
    """6x6 spatial inertia (Pinocchio's [linear; angular] order) about the frame origin,
    from one link's s = [m, mx, my, mz, XX, XY, XZ, YY, YZ, ZZ]; linear in s."""
    m, h = si[0], np.asarray(si[1:4])
    _, _, _, _, xx, xy, xz, yy, yz, zz = si
    Y = np.zeros((6, 6))
    Y[:3, :3] = m * np.eye(3)
    Y[:3, 3:] = -_skew(h)
    Y[3:, :3] = _skew(h)
    Y[3:, 3:] = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
    return Y


def _pinocchio_from_spatial(Y) -> np.ndarray:
    """6x6 -> [m, hx, hy, hz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] (Pinocchio order)."""
    S = Y[3:, :3]
    h = np.array([S[2, 1], S[0, 2], S[1, 0]])
    I = Y[3:, 3:]
    return np.array([Y[0, 0], *h, I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]])


def standard_to_pinocchio_matrix(arm: Arm) -> np.ndarray:
    """A (10N x 10N, block diagonal) with pinocchio_parameters = A @ s, s in frame i and the
    conventions order. Inertia changes frame as Y_J = X^-T Y_i X^-1 with X = jMi.action
    (from kinetic-energy invariance, v_J = X v_i), which is linear in s."""
    A = np.zeros((10 * arm.n, 10 * arm.n))
    for i, joint in enumerate(arm.joints):
        _, post = split_joint(arm.convention, joint)
        Xinv = np.linalg.inv(_se3(post).action)
        for k in range(10):
            e = np.zeros(10)
            e[k] = 1.0
            YJ = Xinv.T @ _spatial_from_standard(e) @ Xinv
            A[10 * i:10 * i + 10, 10 * i + k] = _pinocchio_from_spatial(YJ)
    return A


def standard_regressor(arm: Arm, q, qd, qdd, with_gravity: bool = True) -> np.ndarray:
    """N x 10N regressor Y with tau = Y @ s, s the standard parameters of docs/conventions.md
    (frame i, order m, mx, my, mz, XX, XY, XZ, YY, YZ, ZZ)."""
    return joint_torque_regressor(arm, q, qd, qdd, with_gravity) @ standard_to_pinocchio_matrix(arm)


# --- sampled regressors and their numerical ranks ---------------------------------------

KINDS = ("gravity", "inertia", "full")


def _random_q(arm: Arm, rng) -> np.ndarray:
    return np.array([rng.uniform(-np.pi, np.pi) if j[0] == "revolute" else rng.uniform(-0.5, 0.5)
                     for j in arm.joints])


def sampled_regressor(arm: Arm, kind: str, n_samples: int = 40, seed: int = 0,
                      basis: str = "pinocchio") -> np.ndarray:
    """Stack of regressors at random states.
    gravity: Y(q, 0, 0);  full: Y(q, qd, qdd);  inertia: the rows of the stacked upper
    triangle of M (M11, M12, ..., MNN), column k of M being Y(q, 0, e_k) without gravity.
    basis: 'pinocchio' (Pinocchio's parameters) or 'standard' (s of docs/conventions.md)."""
    if kind not in KINDS:
        raise ValueError(kind)
    rng = np.random.default_rng(seed)
    n = arm.n
    reg = joint_torque_regressor if basis == "pinocchio" else standard_regressor
    zero = np.zeros(n)
    blocks = []
    for _ in range(n_samples):
        q = _random_q(arm, rng)
        if kind == "gravity":
            blocks.append(reg(arm, q, zero, zero))
        elif kind == "full":
            blocks.append(reg(arm, q, rng.standard_normal(n), rng.standard_normal(n)))
        else:
            cols = [reg(arm, q, zero, np.eye(n)[k], with_gravity=False) for k in range(n)]
            rows = [cols[k][j] for j in range(n) for k in range(j, n)]  # M_jk, j <= k
            blocks.append(np.array(rows))
    return np.vstack(blocks)


def regressor_rank(arm: Arm, kind: str, n_samples: int = 40, seed: int = 0, rtol: float = 1e-9) -> int:
    """Numerical rank (SVD, tolerance rtol * largest singular value) of the sampled regressor."""
    sv = np.linalg.svd(sampled_regressor(arm, kind, n_samples, seed), compute_uv=False)
    return int(np.sum(sv > rtol * sv[0]))
