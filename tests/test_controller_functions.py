"""The controller functions of the generated C (Coriolis matrix, M_dot, Slotine-Li regressor,
forward dynamics, derivatives), compiled with cffi, on every example arm: against the numpy
Lagrangian oracle (Christoffel symbols from dM/dq by complex step), against Pinocchio
(computeCoriolisMatrix, aba, computeRNEADerivatives, computeABADerivatives) and against the
identities they must satisfy, at random states and random consistent parameters, 1e-9 relative.
At 1000 states the Lagrangian is the vectorised one (oracles/lagrangian_batch.py: dM/dq and
dg/dq by complex step over every state at once), itself checked against lagrangian.py."""

from __future__ import annotations

import numpy as np
from oracles import lagrangian as lag
from oracles.lagrangian_batch import Lagrangian
from oracles import pinocchio_control as pin_control
from oracles.random_params import random_parameters
from test_generated_c import random_state, rel_err

N_STATES = 100
TOL = 1e-9


def states(built, seed, count=N_STATES):
    rng = np.random.default_rng(seed)
    p = random_parameters(built.robot.dof, seed=seed + 100)
    s = built.c("standard_from_dynamic", p)
    for _ in range(count):
        yield (p, s, *random_state(built, rng))


def test_coriolis_matrix_is_the_christoffel_one(built):
    worst = {}
    for p, s, q, qd, _ in states(built, 1):
        C = built.c("coriolis_matrix", q, qd, s)
        L = Lagrangian(built.arm, p)  # on one state; checked against lagrangian.py in the 1000-state test
        christoffel = L.coriolis_matrix(q[None], qd[None])[0]
        M_dot = np.einsum("kij,k->ij", L.mass_matrix_derivatives(q[None])[0], qd)
        checks = {"C = sum_k Gamma_ijk qd_k": (C, christoffel),
                  "Pinocchio computeCoriolisMatrix": (C, pin_control.coriolis_matrix(built.arm, p, q, qd)),
                  "C qd = c": (C @ qd, L.coriolis(q[None], qd[None])[0]),
                  "M_dot": (built.c("mass_matrix_derivative", q, qd, s), M_dot),
                  "M_dot - 2C skew": ((M_dot - 2 * C) + (M_dot - 2 * C).T, np.zeros_like(C))}
        for name, (got, want) in checks.items():
            worst[name] = max(worst.get(name, 0.0), rel_err(got, want))
    assert all(err < TOL for err in worst.values()), worst


def test_slotine_li_regressor(built):
    n = built.robot.dof
    rng = np.random.default_rng(3)
    worst = {}
    for p, s, q, qd, qdd in states(built, 2):
        pi = built.c("pi_full", p)
        qr_d, qr_dd = rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)
        Y = built.c("regressor_slotine_li", q, qd, qr_d, qr_dd)
        L = Lagrangian(built.arm, p)
        want = L.mass_matrix(q[None])[0] @ qr_dd + L.coriolis_matrix(q[None], qd[None])[0] @ qr_d + L.gravity(q[None])[0]
        checks = {"Y pi = M qr_dd + C qr_d + g": (Y @ pi, want),
                  "Y(q, qd, qd, qdd) pi = rnea": (built.c("regressor_slotine_li", q, qd, qd, qdd) @ pi,
                                                  built.c("rnea", q, qd, qdd, s)),
                  "Y(q, qd, qd, qdd) = regressor": (built.c("regressor_slotine_li", q, qd, qd, qdd),
                                                    built.c("regressor", q, qd, qdd))}
        for name, (got, want) in checks.items():
            worst[name] = max(worst.get(name, 0.0), rel_err(got, want))
    assert all(err < TOL for err in worst.values()), worst


def test_forward_dynamics(built):
    worst = {}
    for p, s, q, qd, qdd in states(built, 4):
        tau = built.c("rnea", q, qd, qdd, s)
        L = Lagrangian(built.arm, p)
        M = L.mass_matrix(q[None])[0]
        bias = L.coriolis(q[None], qd[None])[0] + L.gravity(q[None])[0]
        checks = {"FD(ID(qdd)) = qdd": (built.c("forward_dynamics", q, qd, tau, s), qdd),
                  "Lagrangian M^-1 (tau - c - g)": (built.c("forward_dynamics", q, qd, tau, s),
                                                    np.linalg.solve(M, tau - bias)),
                  "Pinocchio aba": (built.c("forward_dynamics", q, qd, tau, s),
                                    pin_control.forward_dynamics(built.arm, p, q, qd, tau))}
        for name, (got, want) in checks.items():
            worst[name] = max(worst.get(name, 0.0), rel_err(got, want))
    assert all(err < TOL for err in worst.values()), worst


def central_differences(f, q, qd, h=1e-6):
    """[df/dq | df/dqd] of a vector function f(q, qd) by central differences."""
    n = q.size
    D = np.zeros((n, 2 * n))
    for k in range(2 * n):
        e = np.zeros(2 * n)
        e[k] = h
        D[:, k] = (f(q + e[:n], qd + e[n:]) - f(q - e[:n], qd - e[n:])) / (2 * h)
    return D


def test_rnea_derivatives(built):
    worst = {}
    for p, s, q, qd, qdd in states(built, 5, count=30):
        D = built.c("rnea_derivatives", q, qd, qdd, s)
        dq, dv = pin_control.rnea_derivatives(built.arm, p, q, qd, qdd)
        numeric = central_differences(lambda a, b: built.c("rnea", a, b, qdd, s), q, qd)
        worst["Pinocchio computeRNEADerivatives"] = max(worst.get("Pinocchio computeRNEADerivatives", 0.0),
                                                       rel_err(D, np.hstack([dq, dv])))
        worst["central differences of rnea"] = max(worst.get("central differences of rnea", 0.0), rel_err(D, numeric))
    assert worst["Pinocchio computeRNEADerivatives"] < TOL, worst
    assert worst["central differences of rnea"] < 1e-7, worst  # the differences' own truncation and rounding


def test_forward_dynamics_derivatives(built):
    worst = {}
    for p, s, q, qd, qdd in states(built, 6, count=30):
        tau = built.c("rnea", q, qd, qdd, s)
        D = built.c("forward_dynamics_derivatives", q, qd, tau, s)
        dq, dv = pin_control.aba_derivatives(built.arm, p, q, qd, tau)
        M = lag.mass_matrix(built.arm, q, p)
        through_rnea = -np.linalg.solve(M, built.c("rnea_derivatives", q, qd, qdd, s))
        numeric = central_differences(lambda a, b: built.c("forward_dynamics", a, b, tau, s), q, qd)
        checks = {"Pinocchio computeABADerivatives": (D, np.hstack([dq, dv])),
                  "-M^-1 d rnea (Lagrangian M)": (D, through_rnea)}
        for name, (got, want) in checks.items():
            worst[name] = max(worst.get(name, 0.0), rel_err(got, want))
        worst["central differences of FD"] = max(worst.get("central differences of FD", 0.0), rel_err(D, numeric))
    assert worst["Pinocchio computeABADerivatives"] < TOL and worst["-M^-1 d rnea (Lagrangian M)"] < TOL, worst
    assert worst["central differences of FD"] < 1e-6, worst


MANY = 1000  # the count: every C call batched (one C loop), Pinocchio in a python loop


def many_states(built, seed, count=MANY):
    rng = np.random.default_rng(seed)
    Q, QD, QDD = (np.array(x) for x in zip(*(random_state(built, rng) for _ in range(count))))
    return Q, QD, QDD


def per_state_rel_err(got, want) -> float:
    """The largest over states of max |got - want| / max(1, max |want|) of that state."""
    got, want = (np.asarray(x).reshape(len(x), -1) for x in (got, want))
    return float(np.max(np.max(np.abs(got - want), axis=1) / np.maximum(1.0, np.max(np.abs(want), axis=1))))


def test_at_1000_states_against_pinocchio_and_the_identities(built):
    p = random_parameters(built.robot.dof, seed=21)
    s, pi = built.c("standard_from_dynamic", p), built.c("pi_full", p)
    Q, QD, QDD = many_states(built, 20)
    pin_batch = pin_control.Batch(built.arm, p)
    batch = built.c.batch
    tau = batch("rnea", Q, QD, QDD, s)
    C, Md = batch("coriolis_matrix", Q, QD, s), batch("mass_matrix_derivative", Q, QD, s)
    skew = Md - 2 * C
    checks = {
        "rnea = Pinocchio rnea": (tau, pin_batch.rnea(Q, QD, QDD)),
        "C = computeCoriolisMatrix": (C, pin_batch.coriolis_matrix(Q, QD)),
        "M_dot - 2C skew-symmetric": (skew + skew.transpose(0, 2, 1), np.zeros_like(skew)),
        "C qd + g = rnea(q, qd, 0)": (np.einsum("tij,tj->ti", C, QD) + batch("gravity", Q, s),
                                      batch("rnea", Q, QD, np.zeros_like(QD), s)),
        "Y(q, qd, qd, qdd) pi = rnea": (batch("regressor_slotine_li", Q, QD, QD, QDD) @ pi, tau),
        "forward_dynamics = aba": (batch("forward_dynamics", Q, QD, tau, s), pin_batch.forward_dynamics(Q, QD, tau)),
        "FD(ID(qdd)) = qdd": (batch("forward_dynamics", Q, QD, tau, s), QDD),
        "rnea_derivatives = computeRNEADerivatives": (batch("rnea_derivatives", Q, QD, QDD, s),
                                                     pin_batch.rnea_derivatives(Q, QD, QDD)),
        "forward_dynamics_derivatives = computeABADerivatives": (batch("forward_dynamics_derivatives", Q, QD, tau, s),
                                                                 pin_batch.aba_derivatives(Q, QD, tau)),
    }
    worst = {name: per_state_rel_err(got, want) for name, (got, want) in checks.items()}
    assert all(err < TOL for err in worst.values()), worst


def test_slotine_li_identity_at_1000_states(built):
    """Y(q, qd, qr_d, qr_dd) pi = M qr_dd + C qr_d + g, with M, C, g the generated ones (each
    checked against its oracle elsewhere), at independent reference velocities and accelerations."""
    p = random_parameters(built.robot.dof, seed=23)
    s, pi = built.c("standard_from_dynamic", p), built.c("pi_full", p)
    Q, QD, _ = many_states(built, 22)
    rng = np.random.default_rng(24)
    QRD, QRDD = rng.uniform(-2, 2, Q.shape), rng.uniform(-3, 3, Q.shape)
    batch = built.c.batch
    want = (np.einsum("tij,tj->ti", batch("mass_matrix", Q, s), QRDD)
            + np.einsum("tij,tj->ti", batch("coriolis_matrix", Q, QD, s), QRD) + batch("gravity", Q, s))
    assert per_state_rel_err(batch("regressor_slotine_li", Q, QD, QRD, QRDD) @ pi, want) < TOL


def test_at_1000_states_against_the_lagrangian(built):
    """Every controller function against the vectorised Lagrangian oracle (no Newton-Euler, no
    Pinocchio): C = Gamma qd, M_dot = dM/dq qd, FD = M^-1 (tau - c - g), Slotine-Li = M qr_dd +
    C qr_d + g, d tau / d qd = 2 C (c is quadratic in qd: d(qd^T Gamma_i qd) / d qd = 2 Gamma_i qd;
    rnea has no friction), d tau / d q at qd = 0 = dM/dq qdd + dg/dq, and the FD derivatives =
    -M^-1 [d tau / d q | d tau / d qd]."""
    n = built.robot.dof
    p = random_parameters(n, seed=25)
    s, pi = built.c("standard_from_dynamic", p), built.c("pi_full", p)
    Q, QD, QDD = many_states(built, 26)
    rng = np.random.default_rng(27)
    QRD, QRDD = rng.uniform(-2, 2, Q.shape), rng.uniform(-3, 3, Q.shape)
    L = Lagrangian(built.arm, p)
    M, g, dM = L.mass_matrix(Q), L.gravity(Q), L.mass_matrix_derivatives(Q)
    C = L.coriolis_matrix(Q, QD)
    mv = lambda A, x: np.einsum("tij,tj->ti", A, x)  # noqa: E731  (per-state matrix times vector)
    batch = built.c.batch
    tau = batch("rnea", Q, QD, QDD, s)
    D = batch("rnea_derivatives", Q, QD, QDD, s)
    D_rest = batch("rnea_derivatives", Q, np.zeros_like(QD), QDD, s)
    checks = {
        "batch oracle = lagrangian.py (3 states)": (
            np.array([np.einsum("ijk,k->ij", lag.christoffel(built.arm, Q[t], p), QD[t]) for t in range(3)]), C[:3]),
        "rnea = M qdd + c + g": (tau, mv(M, QDD) + mv(C, QD) + g),
        "coriolis_matrix = Gamma qd": (batch("coriolis_matrix", Q, QD, s), C),
        "mass_matrix_derivative = dM/dq qd": (batch("mass_matrix_derivative", Q, QD, s), np.einsum("tkij,tk->tij", dM, QD)),
        "forward_dynamics = M^-1 (tau - c - g)": (batch("forward_dynamics", Q, QD, tau, s),
                                                  np.linalg.solve(M, (tau - mv(C, QD) - g)[..., None])[..., 0]),
        "Slotine-Li Y pi = M qr_dd + C qr_d + g": (batch("regressor_slotine_li", Q, QD, QRD, QRDD) @ pi,
                                                   mv(M, QRDD) + mv(C, QRD) + g),
        "d tau / d qd = 2 C": (D[:, :, n:], 2 * C),
        "d tau / d q at qd = 0 = dM/dq qdd + dg/dq": (D_rest[:, :, :n],
                                                     np.einsum("tkij,tj->tik", dM, QDD) + L.gravity_derivatives(Q)),
        "forward_dynamics_derivatives = -M^-1 D": (batch("forward_dynamics_derivatives", Q, QD, tau, s),
                                                   -np.linalg.solve(M, D)),
    }
    worst = {name: per_state_rel_err(got, want) for name, (got, want) in checks.items()}
    assert all(err < TOL for err in worst.values()), worst
