"""A plain numeric Lagrangian model, from first principles (no Newton-Euler).

    M(q)   = sum_i m_i Jv_i^T Jv_i + Jw_i^T R_i I_i R_i^T Jw_i
    V(q)   = -sum_i m_i g0^T r_ci,            g(q) = dV/dq
    c(q,qd)_i = sum_jk Gamma_ijk qd_j qd_k,   Gamma from dM/dq (Christoffel symbols)
    tau    = M qdd + c + g

dM/dq_k is taken by complex-step differentiation: every operation on q below is
analytic (sin, cos, products, plain transposes -- never conjugates or abs), so
Im(M(q + i h e_k)) / h is dM/dq_k to machine precision with h = 1e-30, without the
cancellation error of finite differences.
"""
from __future__ import annotations

import numpy as np

from .arm import Arm

_H_CS = 1e-30  # complex step


# --- elementary homogeneous transforms (dtype follows the argument: real or complex) ---

def _rotz(t):
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4, dtype=np.result_type(t, float))
    T[0, 0], T[0, 1], T[1, 0], T[1, 1] = c, -s, s, c
    return T


def _rotx(t):
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4, dtype=np.result_type(t, float))
    T[1, 1], T[1, 2], T[2, 1], T[2, 2] = c, -s, s, c
    return T


def _transz(d):
    T = np.eye(4, dtype=np.result_type(d, float))
    T[2, 3] = d
    return T


def _transx(a):
    T = np.eye(4, dtype=np.result_type(a, float))
    T[0, 3] = a
    return T


def dh_transform(convention: str, a, alpha, d, theta) -> np.ndarray:
    """T(i-1, i) for one joint, joint variable already added to theta or d."""
    if convention == "standard":
        return _rotz(theta) @ _transz(d) @ _transx(a) @ _rotx(alpha)
    if convention == "modified":
        return _rotx(alpha) @ _transx(a) @ _rotz(theta) @ _transz(d)
    raise ValueError(convention)


def forward_kinematics(arm: Arm, q) -> list:
    """[T_0, T_1, ..., T_N]: 4x4 pose of every DH frame in the base frame (T_0 = I)."""
    q = np.asarray(q)
    T = np.eye(4, dtype=np.result_type(q, float))
    frames = [T]
    for i, (jtype, a, alpha, d, theta) in enumerate(arm.joints):
        if jtype == "revolute":
            theta = theta + q[i]
        else:
            d = d + q[i]
        T = T @ dh_transform(arm.convention, a, alpha, d, theta)
        frames.append(T)
    return frames


def joint_axes(arm: Arm, frames) -> list:
    """[(z_j, o_j)] per joint j in the base frame: the axis direction and a point on it.
    Standard DH: joint j moves about/along z(j-1); modified DH: about/along z(j)."""
    out = []
    for j in range(arm.n):
        T = frames[j] if arm.convention == "standard" else frames[j + 1]
        out.append((T[:3, 2], T[:3, 3]))
    return out


def link_jacobians(arm: Arm, q, p) -> list:
    """Per link i: (r_ci, Jv_i, Jw_i, R_i). r_ci: CoM in the base frame; Jv_i (3xN):
    linear Jacobian of the CoM; Jw_i (3xN): angular Jacobian; R_i: rotation of frame i.
    Geometric Jacobians: revolute j <= i: Jv col = z_j x (r_ci - o_j), Jw col = z_j;
    prismatic j <= i: Jv col = z_j, Jw col = 0; joints beyond i do not move link i."""
    frames = forward_kinematics(arm, q)
    axes = joint_axes(arm, frames)
    p = np.asarray(p, dtype=float).reshape(arm.n, 10)
    dtype = frames[-1].dtype
    out = []
    for i in range(arm.n):
        T = frames[i + 1]
        R = T[:3, :3]
        r_c = R @ p[i, 1:4] + T[:3, 3]
        Jv = np.zeros((3, arm.n), dtype=dtype)
        Jw = np.zeros((3, arm.n), dtype=dtype)
        for j in range(i + 1):
            z, o = axes[j]
            if arm.joints[j][0] == "revolute":
                Jv[:, j] = np.cross(z, r_c - o)
                Jw[:, j] = z
            else:
                Jv[:, j] = z
        out.append((r_c, Jv, Jw, R))
    return out


def _inertia_about_com(pi) -> np.ndarray:
    _, _, _, _, xx, xy, xz, yy, yz, zz = pi
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)


def mass_matrix(arm: Arm, q, p) -> np.ndarray:
    """M(q) = sum_i m_i Jv_i^T Jv_i + Jw_i^T R_i I_i R_i^T Jw_i (I_i about the CoM, frame i axes)."""
    P = np.asarray(p, dtype=float).reshape(arm.n, 10)
    jac = link_jacobians(arm, q, p)
    M = np.zeros((arm.n, arm.n), dtype=jac[0][1].dtype)
    for i, (_, Jv, Jw, R) in enumerate(jac):
        m = P[i, 0]
        I0 = R @ _inertia_about_com(P[i]) @ R.T
        M = M + m * Jv.T @ Jv + Jw.T @ I0 @ Jw
    return M


def potential_energy(arm: Arm, q, p) -> float:
    """V(q) = -sum_i m_i g0^T r_ci."""
    P = np.asarray(p, dtype=float).reshape(arm.n, 10)
    V = 0.0
    for i, (r_c, _, _, _) in enumerate(link_jacobians(arm, q, p)):
        V = V - P[i, 0] * arm.gravity @ r_c
    return V


def gravity(arm: Arm, q, p) -> np.ndarray:
    """g(q) = dV/dq = -sum_i Jv_i^T m_i g0."""
    P = np.asarray(p, dtype=float).reshape(arm.n, 10)
    g = np.zeros(arm.n)
    for i, (_, Jv, _, _) in enumerate(link_jacobians(arm, q, p)):
        g -= Jv.T @ (P[i, 0] * arm.gravity)
    return g


def mass_matrix_derivatives(arm: Arm, q, p) -> np.ndarray:
    """dM[k] = dM/dq_k (N x N x N), by complex step (exact to rounding)."""
    q = np.asarray(q, dtype=float)
    dM = np.empty((arm.n, arm.n, arm.n))
    for k in range(arm.n):
        qc = q.astype(complex)
        qc[k] += 1j * _H_CS
        dM[k] = mass_matrix(arm, qc, p).imag / _H_CS
    return dM


def christoffel(arm: Arm, q, p) -> np.ndarray:
    """Gamma[i, j, k] = 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i)."""
    dM = mass_matrix_derivatives(arm, q, p)  # dM[k, i, j] = dM_ij / dq_k
    d = np.transpose(dM, (1, 2, 0))  # d[i, j, k] = dM_ij / dq_k
    return 0.5 * (d + np.transpose(d, (0, 2, 1)) - np.transpose(d, (2, 0, 1)))


def coriolis(arm: Arm, q, qd, p) -> np.ndarray:
    """c(q, qd)_i = sum_jk Gamma_ijk qd_j qd_k."""
    qd = np.asarray(qd, dtype=float)
    return np.einsum("ijk,j,k->i", christoffel(arm, q, p), qd, qd)


def inverse_dynamics(arm: Arm, q, qd, qdd, p) -> np.ndarray:
    """tau = M(q) qdd + c(q, qd) + g(q)."""
    M = mass_matrix(arm, q, p)
    return M @ np.asarray(qdd, dtype=float) + coriolis(arm, q, qd, p) + gravity(arm, q, p)


def stacked_upper(M) -> np.ndarray:
    """The N(N+1)/2 upper-triangular entries row by row: M11, M12, ..., M1N, M22, ..., MNN."""
    M = np.asarray(M)
    return M[np.triu_indices(M.shape[0])]


# --- dynamic p <-> standard s (parallel-axis theorem) -----------------------------------

def standard_from_dynamic(p) -> np.ndarray:
    """Per link [m, cx, cy, cz, Ixx..Izz (CoM)] -> [m, mx, my, mz, XX, XY, XZ, YY, YZ, ZZ]
    with the inertia about the frame origin  I_O = I_C + m (c.c E - c c^T)."""
    P = np.asarray(p, dtype=float).reshape(-1, 10)
    S = np.empty_like(P)
    for i, pi in enumerate(P):
        m, c = pi[0], pi[1:4]
        IO = _inertia_about_com(pi) + m * (c @ c * np.eye(3) - np.outer(c, c))
        S[i] = [m, *(m * c), IO[0, 0], IO[0, 1], IO[0, 2], IO[1, 1], IO[1, 2], IO[2, 2]]
    return S.reshape(-1)


def dynamic_from_standard(s) -> np.ndarray:
    """Inverse of standard_from_dynamic (needs m != 0)."""
    S = np.asarray(s, dtype=float).reshape(-1, 10)
    P = np.empty_like(S)
    for i, si in enumerate(S):
        m = si[0]
        c = si[1:4] / m
        IC = _inertia_about_com(si) - m * (c @ c * np.eye(3) - np.outer(c, c))
        P[i] = [m, *c, IC[0, 0], IC[0, 1], IC[0, 2], IC[1, 1], IC[1, 2], IC[2, 2]]
    return P.reshape(-1)
