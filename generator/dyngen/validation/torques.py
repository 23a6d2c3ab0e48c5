"""Joint torques along a trajectory, two ways, and their comparison (the paper's Sec. IV, Fig. 6).

- newton_euler: the generated recursive Newton-Euler routine with link parameters p;
- from_coefficients: the Lagrangian model built from the base coefficients alone (as the
  paper's [9] does with identified coefficients), tau = M(q) qdd + c(q, qd) + g(q) with
  g = Y_g(q) pi_g, M unstacked from Y_m(q) pi_m, and the Coriolis/centrifugal vector from
  the Christoffel symbols of M:

      c_i = sum_jk Gamma_ijk qd_j qd_k,  Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2,
      i.e. c = Mdot qd - 1/2 d(qd^T M qd)/dq,  Mdot = sum_k dM/dq_k qd_k.

Accuracy of dM/dq_k. Every entry of M (and of Y_m) is, as a function of one joint variable
with the others fixed, a trigonometric polynomial of degree <= 2 in a revolute q_k (frequencies
0, 1, 2: M is a sum of dot products of Jacobian columns and R I R^T, each at most quadratic in
the rotation of joint k) and a polynomial of degree <= 2 in a prismatic q_k. So the default
derivative="exact" uses stencils that are exact for those function classes, with large steps:

  revolute:  f'(x) = w1 [f(x+h) - f(x-h)] + w2 [f(x+2h) - f(x-2h)],  h = 2 pi / 5,
             w1, w2 solving 2 w1 sin(w h) + 2 w2 sin(2 w h) = w for w = 1, 2
             (5-point periodic spectral differentiation);
  prismatic: f'(x) = [f(x+h) - f(x-h)] / (2 h),  h = 0.1 (exact for quadratics).

Only rounding remains. Measured against Newton-Euler with the same parameters on the Table V
trajectory (25 Hz, random consistent parameters, joints 1..N of the knots): max |difference| /
max |tau| = 5e-16 to 1e-15 (LWR, Panda, UR5, Stanford arm), 2e-14 (PUMA 560);
tests/test_validation.py asserts 1e-10 for the LWR.
derivative="fd4" is the generic 4-point central stencil [8(f(x+h) - f(x-h)) - (f(x+2h) - f(x-2h))] / (12 h),
h = 1e-3, for any smooth M: truncation ~h^4 f^(5) / 30 and rounding ~eps |M| / h; measured as above
5e-14 to 8e-14 (LWR, Panda, UR5, Stanford), 3e-12 (PUMA 560), at the same cost (4 evaluations of
Y_m per joint and sample; ~1.2 s for the 2801 samples of Table V at 100 Hz).
"""

from __future__ import annotations

import numpy as np

from ..catalogue import REGRESSOR_GRAVITY, REGRESSOR_INERTIA, RNEA, STANDARD_FROM_DYNAMIC

_H_REVOLUTE = 2.0 * np.pi / 5.0
_W_REVOLUTE = np.linalg.solve(
    2.0 * np.array([[np.sin(_H_REVOLUTE), np.sin(2 * _H_REVOLUTE)],
                    [np.sin(2 * _H_REVOLUTE), np.sin(4 * _H_REVOLUTE)]]),
    np.array([1.0, 2.0]))
_H_PRISMATIC = 0.1
_H_FD4 = 1e-3


def _check_model(model) -> int:
    if model.manifest.get("gravity_symbols"):
        raise ValueError(f"{model.manifest['robot']}: symbolic gravity "
                         f"({', '.join(model.manifest['gravity_symbols'])}) is not supported here")
    return int(model.manifest["dof"])


def _rows(x, n: int, name: str) -> np.ndarray:
    a = np.atleast_2d(np.asarray(x, dtype=float))
    if a.shape[1] != n:
        raise ValueError(f"{name}: expected {n} columns (one per joint), got shape {a.shape}")
    return a


def newton_euler(model, p, q, qd, qdd) -> np.ndarray:
    """tau (T x N) by the generated recursive Newton-Euler routine, s = standard_from_dynamic(p)."""
    n = _check_model(model)
    q, qd, qdd = (_rows(x, n, name) for x, name in ((q, "q"), (qd, "qd"), (qdd, "qdd")))
    s = model(STANDARD_FROM_DYNAMIC.name, np.asarray(p, dtype=float))
    return np.array([model(RNEA.name, a, b, c, s) for a, b, c in zip(q, qd, qdd)])


def _stencils(types, derivative: str):
    """Per joint: (step, [(offset multiple, weight), ...]) so that f'(x) = sum w [f(x+jh) - f(x-jh)]."""
    out = []
    for kind in types:
        if derivative == "exact":
            if kind == "revolute":
                out.append((_H_REVOLUTE, [(1, _W_REVOLUTE[0]), (2, _W_REVOLUTE[1])]))
            else:
                out.append((_H_PRISMATIC, [(1, 0.5 / _H_PRISMATIC)]))
        elif derivative == "fd4":
            out.append((_H_FD4, [(1, 8.0 / (12.0 * _H_FD4)), (2, -1.0 / (12.0 * _H_FD4))]))
        else:
            raise ValueError(f'derivative must be "exact" or "fd4", not {derivative!r}')
    return out


def inertia_and_derivatives(model, pi_m, q, derivative: str = "exact"):
    """M(q) (N x N) and dM/dq (N x N x N, [k] = dM/dq_k) from Y_m(q) pi_m."""
    n = _check_model(model)
    pi_m = np.asarray(pi_m, dtype=float)
    q = np.asarray(q, dtype=float).ravel()
    iu = np.triu_indices(n)  # row by row: M11, M12, ..., M1N, M22, ...

    def unstack(m):
        M = np.zeros((n, n))
        M[iu] = m
        return M + np.triu(M, 1).T

    stacked = model(REGRESSOR_INERTIA.name, q) @ pi_m
    dm = np.zeros((n, stacked.size))
    for k, (h, terms) in enumerate(_stencils(model.manifest["joint_types"], derivative)):
        for j, w in terms:
            up, down = q.copy(), q.copy()
            up[k] += j * h
            down[k] -= j * h
            dm[k] += w * ((model(REGRESSOR_INERTIA.name, up) - model(REGRESSOR_INERTIA.name, down)) @ pi_m)
    return unstack(stacked), np.array([unstack(row) for row in dm])


def coriolis(dM: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """c(q, qd) = Mdot qd - 1/2 d(qd^T M qd)/dq from dM[k] = dM/dq_k (Christoffel symbols of M)."""
    mdot = np.einsum("kij,k->ij", dM, qd)
    return mdot @ qd - 0.5 * np.einsum("kij,i,j->k", dM, qd, qd)


def from_coefficients(model, pi_g, pi_m, q, qd, qdd, derivative: str = "exact") -> np.ndarray:
    """tau (T x N) = M(q) qdd + c(q, qd) + g(q) from the base coefficients pi_g, pi_m only."""
    n = _check_model(model)
    q, qd, qdd = (_rows(x, n, name) for x, name in ((q, "q"), (qd, "qd"), (qdd, "qdd")))
    pi_g = np.asarray(pi_g, dtype=float)
    tau = np.empty_like(q)
    for row, (a, b, c) in enumerate(zip(q, qd, qdd)):
        M, dM = inertia_and_derivatives(model, pi_m, a, derivative)
        tau[row] = M @ c + coriolis(dM, b) + model(REGRESSOR_GRAVITY.name, a) @ pi_g
    return tau


def compare(tau_a, tau_b) -> dict:
    """Per joint: max_abs = max_t |tau_a - tau_b|, rms of the difference, and peak = max_t |tau_b|."""
    a, b = np.atleast_2d(np.asarray(tau_a, dtype=float)), np.atleast_2d(np.asarray(tau_b, dtype=float))
    if a.shape != b.shape:
        raise ValueError(f"torque arrays differ in shape: {a.shape} vs {b.shape}")
    d = a - b
    return {"max_abs": np.abs(d).max(axis=0), "rms": np.sqrt(np.mean(d * d, axis=0)),
            "peak": np.abs(b).max(axis=0)}
