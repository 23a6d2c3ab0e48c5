"""The generated C, compiled with cffi, against the numpy Lagrangian and Pinocchio.

Every example arm, 100+ random states, random consistent parameters and the YAML's
nominal ones: Y_g pi_g = g, Y_m pi_m = stacked M, Y pi = tau = Newton-Euler, to 1e-9.
"""

from __future__ import annotations

import numpy as np
import pytest
from oracles import lagrangian as lag
from oracles import pinocchio_arm as pin_arm
from oracles.random_params import random_parameters

N_STATES = 100
TOL = 1e-9


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, float(np.max(np.abs(b)))))


def random_state(built, rng):
    n = built.robot.dof
    q = rng.uniform(-np.pi, np.pi, n)
    for i, joint in enumerate(built.robot.joints):
        if not joint.revolute:
            q[i] = rng.uniform(0.2, 1.0)
    return q, rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)


def parameter_sets(built):
    return {"random consistent": random_parameters(built.robot.dof, seed=11), "nominal": built.nominal}


def test_standard_from_dynamic_matches_oracle(built):
    for p in parameter_sets(built).values():
        assert rel_err(built.c("standard_from_dynamic", p), lag.standard_from_dynamic(p)) < 1e-14


def test_models_and_regressors_match_lagrangian(built):
    rng = np.random.default_rng(1)
    n = built.robot.dof
    worst = {}
    for label, p in parameter_sets(built).items():
        s = built.c("standard_from_dynamic", p)
        pi_g, pi_m, pi = (built.c(f"pi_{k}", p) for k in ("gravity", "inertia", "full"))
        for _ in range(N_STATES):
            q, qd, qdd = random_state(built, rng)
            M = lag.mass_matrix(built.arm, q, p)
            g = lag.gravity(built.arm, q, p)
            tau = lag.inverse_dynamics(built.arm, q, qd, qdd, p)
            checks = {
                "rnea": (built.c("rnea", q, qd, qdd, s), tau),
                "gravity": (built.c("gravity", q, s), g),
                "mass_matrix": (built.c("mass_matrix", q, s), M),
                "Y_g pi_g": (built.c("regressor_gravity", q) @ pi_g, g),
                "Y_m pi_m": (built.c("regressor_inertia", q) @ pi_m, lag.stacked_upper(M)),
                "Y pi": (built.c("regressor", q, qd, qdd) @ pi, tau),
                "rnea(q, 0, 0) = g": (built.c("rnea", q, np.zeros(n), np.zeros(n), s), g),
            }
            for name, (got, want) in checks.items():
                worst[name] = max(worst.get(name, 0.0), rel_err(got, want))
    assert all(err < TOL for err in worst.values()), worst


def test_mass_matrix_symmetric_positive_definite(built):
    rng = np.random.default_rng(2)
    s = built.c("standard_from_dynamic", random_parameters(built.robot.dof, seed=3))
    for _ in range(N_STATES):
        q, _, _ = random_state(built, rng)
        M = built.c("mass_matrix", q, s)
        assert np.allclose(M, M.T, rtol=0, atol=1e-14)
        assert np.linalg.eigvalsh(M).min() > 0


def test_rnea_matches_pinocchio(built):
    rng = np.random.default_rng(4)
    p = random_parameters(built.robot.dof, seed=5)
    s = built.c("standard_from_dynamic", p)
    worst = 0.0
    for _ in range(N_STATES):
        q, qd, qdd = random_state(built, rng)
        worst = max(worst, rel_err(built.c("rnea", q, qd, qdd, s), pin_arm.rnea(built.arm, p, q, qd, qdd)))
    assert worst < TOL


def test_inverse_dynamics_over_base_coefficients(built):
    """ID(q, qd, qdd, pi_full(p)) = rnea(q, qd, qdd, s(p)) = Pinocchio's rnea, and for coefficients
    no parameters give (identified ones need not be consistent) ID(pi) = Y(q, qd, qdd) pi."""
    rng = np.random.default_rng(6)
    n = built.robot.dof
    worst = {}
    for label, p in parameter_sets(built).items():
        s = built.c("standard_from_dynamic", p)
        pi = built.c("pi_full", p)
        arbitrary = rng.normal(size=pi.shape) * np.abs(pi).max()
        for _ in range(N_STATES):
            q, qd, qdd = random_state(built, rng)
            tau = built.c("inverse_dynamics", q, qd, qdd, pi)
            checks = {"rnea": (tau, built.c("rnea", q, qd, qdd, s)),
                      "pinocchio": (tau, pin_arm.rnea(built.arm, p, q, qd, qdd)),
                      "Y pi, any pi": (built.c("inverse_dynamics", q, qd, qdd, arbitrary),
                                       built.c("regressor", q, qd, qdd) @ arbitrary),
                      "gravity": (built.c("inverse_dynamics", q, np.zeros(n), np.zeros(n), pi), lag.gravity(built.arm, q, p))}
            for name, (got, want) in checks.items():
                worst[name] = max(worst.get(name, 0.0), rel_err(got, want))
    assert all(err < TOL for err in worst.values()), worst


def test_rnea_nominal_is_rnea_at_the_nominal_parameters(built):
    """rnea_nominal (the YAML's nominal parameters folded in as numbers) against rnea with s(p)
    and Pinocchio's rnea at the same p, oracles' reading of the YAML, 1000 random states."""
    rng = np.random.default_rng(12)
    p = built.nominal
    s = built.c("standard_from_dynamic", p)
    worst = {"rnea": 0.0, "pinocchio": 0.0}
    for _ in range(1000):
        q, qd, qdd = random_state(built, rng)
        tau = built.c("rnea_nominal", q, qd, qdd)
        worst["rnea"] = max(worst["rnea"], rel_err(tau, built.c("rnea", q, qd, qdd, s)))
        worst["pinocchio"] = max(worst["pinocchio"], rel_err(tau, pin_arm.rnea(built.arm, p, q, qd, qdd)))
    assert all(err < TOL for err in worst.values()), worst


def test_joint_angles_far_from_zero_and_on_quadrant_edges(lwr):
    """The generated sincos (reduction by pi/2, then polynomials, libm's beyond |q| = 1e5) at
    angles of every size and next to the edges between its quadrants, against numpy's sin and
    cos in the Lagrangian oracle at the same double angles."""
    rng = np.random.default_rng(8)
    p, n = lwr.nominal, lwr.robot.dof
    s = lwr.c("standard_from_dynamic", p)
    edges = [k * np.pi / 4 + d for k in range(-9, 10) for d in (-1e-12, 0.0, 1e-12)]
    sizes = [x * m for m in (1.0, 10.0, 1e3, 9.9e4, 1.01e5, 1e7) for x in (-1.0, 1.0)]
    worst = 0.0
    for angle in edges + sizes + list(rng.uniform(-2e5, 2e5, 50)):
        q = rng.uniform(-np.pi, np.pi, n)
        q[rng.integers(n)] = angle
        q[1 + rng.integers(n - 1)] = angle  # joint 1 alone would not show in g (vertical axis)
        worst = max(worst, rel_err(lwr.c("gravity", q, s), lag.gravity(lwr.arm, q, p)))
    assert worst < TOL


@pytest.mark.parametrize("kind", ["gravity", "inertia", "full"])
def test_base_count_is_numerical_rank_of_pinocchio_regressor(built, kind):
    """Minimal means minimal: the count equals the numerical rank, not just full column rank."""
    assert built.bases[kind].rank == pin_arm.regressor_rank(built.arm, kind, n_samples=40, seed=3)


@pytest.mark.parametrize("kind", ["gravity", "inertia", "full"])
def test_base_regressor_has_full_column_rank(built, kind):
    rng = np.random.default_rng(6)
    name = {"gravity": "regressor_gravity", "inertia": "regressor_inertia", "full": "regressor"}[kind]
    rows = []
    for _ in range(30):
        q, qd, qdd = random_state(built, rng)
        rows.append(built.c(name, q, qd, qdd) if kind == "full" else built.c(name, q))
    Y = np.vstack(rows)
    sv = np.linalg.svd(Y, compute_uv=False)
    assert Y.shape[1] == built.bases[kind].rank
    assert sv[-1] > 1e-8 * sv[0]


def test_coefficient_jacobians_match_central_differences(built):
    p = random_parameters(built.robot.dof, seed=8)
    for kind in ("gravity", "inertia", "full"):
        J = built.c(f"pi_{kind}_jacobian", p)
        numeric = np.zeros_like(J)
        for j in range(p.size):
            h = 1e-6 * max(1.0, abs(p[j]))
            up, down = p.copy(), p.copy()
            up[j] += h
            down[j] -= h
            numeric[:, j] = (built.c(f"pi_{kind}", up) - built.c(f"pi_{kind}", down)) / (2 * h)
        assert rel_err(J, numeric) < 1e-8, kind
