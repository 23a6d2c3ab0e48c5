"""The Lagrangian oracle of lagrangian.py over many states at once (numpy, vectorised).

The same first principles, the same formulas, on arrays with a leading state axis:

    M(q)   = sum_i m_i Jv_i^T Jv_i + Jw_i^T R_i I_i R_i^T Jw_i
    g(q)   = -sum_i Jv_i^T m_i g0
    dM/dq_k = Im M(q + i h e_k) / h,  h = 1e-30 (complex step: M is built only from analytic
             operations of q -- sin, cos, products, plain transposes -- so this is exact to
             rounding, with no finite-difference cancellation)
    Gamma_ijk = 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i),  C_ij = sum_k Gamma_ijk qd_k,  c = C qd

lagrangian.py takes 46 ms per state for the Christoffel symbols (python loops over links,
joints and directions); here one call handles every state and every complex direction
together (the state axis is S x (1 + N) long), so 1000 states take well under a second.
It is checked against lagrangian.py state by state (tests/test_controller_functions.py).

    L = Lagrangian(arm, p)            # p: the oracle's dynamic parameters (10 per link)
    L.mass_matrix(Q)                  # (S, N, N)
    L.gravity(Q)                      # (S, N)
    L.mass_matrix_derivatives(Q)      # (S, N, N, N): [t, k, i, j] = dM_ij / dq_k
    L.gravity_derivatives(Q)          # (S, N, N): [t, i, k] = dg_i / dq_k
    L.christoffel(Q), L.coriolis_matrix(Q, QD), L.coriolis(Q, QD), L.inverse_dynamics(Q, QD, QDD)
"""
from __future__ import annotations

import numpy as np

from .arm import Arm

_H_CS = 1e-30  # complex step


def _eye(count: int, dtype) -> np.ndarray:
    return np.broadcast_to(np.eye(4, dtype=dtype), (count, 4, 4)).copy()


def _rotz(t):
    T = _eye(len(t), t.dtype)
    c, s = np.cos(t), np.sin(t)
    T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = c, -s, s, c
    return T


def _rotx(t):
    T = _eye(len(t), t.dtype)
    c, s = np.cos(t), np.sin(t)
    T[:, 1, 1], T[:, 1, 2], T[:, 2, 1], T[:, 2, 2] = c, -s, s, c
    return T


def _transz(d):
    T = _eye(len(d), d.dtype)
    T[:, 2, 3] = d
    return T


def _transx(a):
    T = _eye(len(a), a.dtype)
    T[:, 0, 3] = a
    return T


def _dh(convention: str, a, alpha, d, theta):
    """T(i-1, i) per state; every argument an array over states."""
    if convention == "standard":
        return _rotz(theta) @ _transz(d) @ _transx(a) @ _rotx(alpha)
    if convention == "modified":
        return _rotx(alpha) @ _transx(a) @ _rotz(theta) @ _transz(d)
    raise ValueError(convention)


def _complex_steps(Q) -> np.ndarray:
    """(S N, N) complex states: row t N + k is q_t + i h e_k."""
    Q = np.asarray(Q, dtype=float)
    S, n = Q.shape
    shifted = np.repeat(Q[:, None, :], n, axis=1).astype(complex)
    shifted[:, np.arange(n), np.arange(n)] += 1j * _H_CS
    return shifted.reshape(S * n, n)


def _inertia_about_com(pi) -> np.ndarray:
    _, _, _, _, xx, xy, xz, yy, yz, zz = pi
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)


class Lagrangian:
    def __init__(self, arm: Arm, p):
        self.arm = arm
        self.P = np.asarray(p, dtype=float).reshape(arm.n, 10)

    def frames(self, Q) -> list:
        """[T_0, ..., T_N], each (S, 4, 4): every DH frame in the base frame."""
        Q = np.asarray(Q)
        S = Q.shape[0]
        T = _eye(S, Q.dtype)
        out = [T]
        for i, (jtype, a, alpha, d, theta) in enumerate(self.arm.joints):
            full = lambda x: np.full(S, x, dtype=Q.dtype)  # noqa: E731
            th, dd = (full(theta) + Q[:, i], full(d)) if jtype == "revolute" else (full(theta), full(d) + Q[:, i])
            T = T @ _dh(self.arm.convention, full(a), full(alpha), dd, th)
            out.append(T)
        return out

    def link_jacobians(self, Q) -> list:
        """Per link i: (r_ci (S, 3), Jv_i (S, 3, N), Jw_i (S, 3, N), R_i (S, 3, 3))."""
        frames = self.frames(Q)
        n, standard = self.arm.n, self.arm.convention == "standard"
        axes = [(F[:, :3, 2], F[:, :3, 3]) for F in (frames[j] if standard else frames[j + 1] for j in range(n))]
        out = []
        for i in range(n):
            R, o_i = frames[i + 1][:, :3, :3], frames[i + 1][:, :3, 3]
            r_c = np.einsum("sab,b->sa", R, self.P[i, 1:4]) + o_i
            Jv = np.zeros((len(r_c), 3, n), dtype=r_c.dtype)
            Jw = np.zeros_like(Jv)
            for j in range(i + 1):
                z, o = axes[j]
                if self.arm.joints[j][0] == "revolute":
                    Jv[:, :, j] = np.cross(z, r_c - o)
                    Jw[:, :, j] = z
                else:
                    Jv[:, :, j] = z
            out.append((r_c, Jv, Jw, R))
        return out

    def mass_matrix(self, Q) -> np.ndarray:
        jac = self.link_jacobians(Q)
        M = 0
        for i, (_, Jv, Jw, R) in enumerate(jac):
            I0 = R @ _inertia_about_com(self.P[i]) @ R.transpose(0, 2, 1)
            M = M + self.P[i, 0] * Jv.transpose(0, 2, 1) @ Jv + Jw.transpose(0, 2, 1) @ I0 @ Jw
        return M

    def gravity(self, Q) -> np.ndarray:
        g = 0
        for i, (_, Jv, _, _) in enumerate(self.link_jacobians(Q)):
            g = g - np.einsum("sai,a->si", Jv, self.P[i, 0] * self.arm.gravity)
        return g

    def mass_matrix_derivatives(self, Q) -> np.ndarray:
        """[t, k, i, j] = dM_ij / dq_k at state t: every state and direction in one complex batch."""
        S, n = np.shape(Q)
        return (self.mass_matrix(_complex_steps(Q)).imag / _H_CS).reshape(S, n, n, n)

    def gravity_derivatives(self, Q) -> np.ndarray:
        """[t, i, k] = dg_i / dq_k at state t, by the same complex step."""
        S, n = np.shape(Q)
        return np.transpose((self.gravity(_complex_steps(Q)).imag / _H_CS).reshape(S, n, n), (0, 2, 1))

    def christoffel(self, Q) -> np.ndarray:
        """[t, i, j, k] = Gamma_ijk at state t."""
        d = np.transpose(self.mass_matrix_derivatives(Q), (0, 2, 3, 1))  # [t, i, j, k] = dM_ij / dq_k
        return 0.5 * (d + np.transpose(d, (0, 1, 3, 2)) - np.transpose(d, (0, 3, 1, 2)))

    def coriolis_matrix(self, Q, QD) -> np.ndarray:
        return np.einsum("tijk,tk->tij", self.christoffel(Q), QD)

    def coriolis(self, Q, QD) -> np.ndarray:
        return np.einsum("tij,tj->ti", self.coriolis_matrix(Q, QD), QD)

    def inverse_dynamics(self, Q, QD, QDD) -> np.ndarray:
        return np.einsum("tij,tj->ti", self.mass_matrix(Q), QDD) + self.coriolis(Q, QD) + self.gravity(Q)
