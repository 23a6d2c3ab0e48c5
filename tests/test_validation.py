"""The paper's Sec. IV validation: Table V trajectory, Newton-Euler vs the Lagrangian model from coefficients."""

from __future__ import annotations

import numpy as np
import pytest
from oracles.random_params import random_parameters

from dyngen.extraction.problem import Options
from dyngen.extraction.run import extract
from dyngen.runtime import load
from dyngen.validation import validate
from dyngen.validation.torques import compare, from_coefficients, inertia_and_derivatives, newton_euler
from dyngen.validation.trajectory import TABLE_V, TABLE_V_KNOTS, TABLE_V_TIMES, cubic_through_knots, table_v

# Measured (Options(restarts=8), 100 Hz): N-E with the extracted parameters vs the coefficients
# model, max |difference| per joint 1.6e-05 8.1e-05 1.0e-04 8.4e-05 3.0e-05 7.8e-05 1.3e-05 Nm
# (the extracted parameters reproduce pi_hat to 5e-6); with the V-REP nominal parameters
# 0.46 2.26 1.43 0.35 0.083 0.067 0.0028 Nm.
EXTRACTED_BOUND = 1e-3  # Nm, every joint


# ---------------------------------------------------------------- trajectory

def test_table_v_is_the_papers():
    knots, times = TABLE_V
    h, q = np.pi / 2, np.pi / 4
    alt = np.array([1, -1, 1, -1, 1, -1, 1])
    expected = [np.full(7, h), np.zeros(7), np.full(7, h), -np.full(7, h), np.full(7, h), q * alt, -q * alt, q * alt]
    assert knots.shape == (8, 7)
    np.testing.assert_array_equal(knots, np.array(expected))
    np.testing.assert_array_equal(times, [0, 5, 8, 15, 22, 24, 25.5, 28])
    assert knots is TABLE_V_KNOTS and times is TABLE_V_TIMES


def test_knots_hit_exactly_with_zero_velocity():
    t, q, qd, qdd = table_v(100)
    assert t.size == 2801 and t[0] == 0 and t[-1] == 28
    np.testing.assert_allclose(np.diff(t), 0.01, atol=1e-12)
    for knot, tk in zip(TABLE_V_KNOTS, TABLE_V_TIMES):
        (i,) = np.flatnonzero(t == tk)
        np.testing.assert_array_equal(q[i], knot)
        np.testing.assert_array_equal(qd[i], 0.0)


def test_knots_off_the_sampling_grid_are_included():
    knots = np.array([[0.0, 1.0], [1.0, -1.0], [0.5, 0.0]])
    times = np.array([0.0, 0.333, 1.0])
    t, q, qd, _ = cubic_through_knots(knots, times, 10)
    assert 0.333 in t and np.all(np.diff(t) > 0)
    (i,) = np.flatnonzero(t == 0.333)
    np.testing.assert_array_equal(q[i], knots[1])
    np.testing.assert_array_equal(qd[i], 0.0)
    np.testing.assert_array_equal(q[-1], knots[-1])


def test_position_and_velocity_are_continuous_across_segments():
    t, q, qd, qdd = table_v(1000)
    dt = np.diff(t)[:, None]
    # Lipschitz steps: no jump larger than what the derivative allows over one sample.
    assert np.all(np.abs(np.diff(q, axis=0)) <= np.abs(qd).max() * dt * (1 + 1e-9))
    assert np.all(np.abs(np.diff(qd, axis=0)) <= np.abs(qdd).max() * dt * (1 + 1e-9))
    # Each segment, evaluated on its own, ends where the next one starts, at rest.
    for k in range(1, len(TABLE_V_TIMES) - 1):
        _, qa, qda, _ = cubic_through_knots(TABLE_V_KNOTS[k - 1:k + 1], TABLE_V_TIMES[k - 1:k + 1], 50)
        _, qb, qdb, _ = cubic_through_knots(TABLE_V_KNOTS[k:k + 2], TABLE_V_TIMES[k:k + 2], 50)
        np.testing.assert_array_equal(qa[-1], qb[0])
        np.testing.assert_array_equal(qda[-1], 0.0)
        np.testing.assert_array_equal(qdb[0], 0.0)


def test_acceleration_matches_finite_differences_of_velocity():
    t, q, qd, qdd = table_v(100)
    # qd is quadratic within a segment, so the central difference is exact there; skip knots.
    segment = np.searchsorted(TABLE_V_TIMES, t, side="right")
    inner = np.flatnonzero((segment[:-2] == segment[2:]) & ~np.isin(t[1:-1], TABLE_V_TIMES)) + 1
    central = (qd[inner + 1] - qd[inner - 1]) / (t[inner + 1] - t[inner - 1])[:, None]
    np.testing.assert_allclose(central, qdd[inner], rtol=0, atol=1e-9)
    assert inner.size > 2700
    # and qd from q the same way (q is cubic: central difference error dt^2/6 |jerk|)
    central_q = (q[inner + 1] - q[inner - 1]) / (t[inner + 1] - t[inner - 1])[:, None]
    np.testing.assert_allclose(central_q, qd[inner], rtol=0, atol=5e-4)


# ---------------------------------------------------------------- torques

@pytest.fixture(scope="module")
def model(lwr):
    return load(lwr.c.folder)


@pytest.mark.parametrize("seed", [11, 12])
def test_coefficients_model_equals_newton_euler_for_the_same_parameters(model, seed):
    """Lagrangian from (Y_g pi_g, Y_m pi_m), Coriolis from Christoffel symbols, vs recursive N-E."""
    p = random_parameters(7, seed)
    t, q, qd, qdd = table_v(25)
    tau_ne = newton_euler(model, p, q, qd, qdd)
    tau = from_coefficients(model, model("pi_gravity", p), model("pi_inertia", p), q, qd, qdd)
    diff = compare(tau, tau_ne)
    assert diff["max_abs"].max() <= 1e-10 * diff["peak"].max()
    # the velocity terms are a real part of the check
    velocity_part = tau_ne - newton_euler(model, p, q, 0 * qd, qdd)
    assert np.abs(velocity_part).max() > 1e-2 * diff["peak"].max()


def test_fd4_derivative_agrees_with_the_exact_stencil(model):
    p = random_parameters(7, 5)
    pi_m = model("pi_inertia", p)
    rng = np.random.default_rng(0)
    for q in rng.uniform(-2, 2, (3, 7)):
        M, dM = inertia_and_derivatives(model, pi_m, q)
        M4, dM4 = inertia_and_derivatives(model, pi_m, q, derivative="fd4")
        np.testing.assert_array_equal(M, M4)
        np.testing.assert_allclose(M, model("mass_matrix", q, model("standard_from_dynamic", p)), atol=1e-13)
        np.testing.assert_allclose(dM4, dM, rtol=0, atol=1e-9 * np.abs(M).max())
        assert np.abs(dM).max() > 1e-2 * np.abs(M).max()


def test_compare_reports_per_joint_max_and_rms():
    a = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])
    b = a + np.array([[0.1, 0.0], [-0.3, 0.0], [0.0, 0.2]])
    d = compare(a, b)
    np.testing.assert_allclose(d["max_abs"], [0.3, 0.2])
    np.testing.assert_allclose(d["rms"], [np.sqrt(0.1 / 3), np.sqrt(0.04 / 3)])
    np.testing.assert_allclose(d["peak"], [5.0, 6.2])  # of the second argument


# ---------------------------------------------------------------- the LWR, as in the paper's Fig. 6

@pytest.fixture(scope="module")
def lwr_validation(lwr, model, tmp_path_factory):
    ex = extract(lwr.robot, lwr.bases, lwr.c.folder, Options(restarts=8))
    pi_g = np.linalg.solve(ex.targets["gravity"].W, ex.targets["gravity"].v)
    pi_m = np.linalg.solve(ex.targets["inertia"].W, ex.targets["inertia"].v)
    out = tmp_path_factory.mktemp("validation")
    result = validate(lwr.yaml, lwr.c.folder, ex.p, pi_g, pi_m, out, rate_hz=100, model=model)
    return result, pi_g, pi_m


def test_extracted_parameters_reproduce_the_coefficients_torques(lwr_validation):
    result, _, _ = lwr_validation
    assert result["samples"] == 2801
    max_abs = np.array(result["max_abs"])
    assert max_abs.shape == (7,)
    assert np.all(max_abs < EXTRACTED_BOUND), max_abs
    assert np.all(np.array(result["rms"]) <= max_abs)
    assert max(result["peak"]) > 30  # joint 2 carries ~41 Nm: the comparison is not trivial


def test_nominal_parameters_would_fail_the_bound(lwr, model, lwr_validation):
    result, _, _ = lwr_validation
    t = result["torques"]["t"]
    _, q, qd, qdd = table_v(100)
    assert t.size == q.shape[0]
    tau_nominal = newton_euler(model, lwr.nominal, q, qd, qdd)
    max_abs = compare(tau_nominal, result["torques"]["coefficients"])["max_abs"]
    assert np.all(max_abs > EXTRACTED_BOUND), max_abs  # every joint, joint 7 included (2.8e-3 Nm)
    assert max_abs.max() > 1.0  # joint 2: ~2.3 Nm


def test_figures_and_table_are_written(lwr_validation):
    result, _, _ = lwr_validation
    paths = result["paths"]
    for key in ("trajectory", "torques"):
        assert paths[key].suffix == ".png"
        assert paths[key].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert paths[key].stat().st_size > 10_000
    text = paths["markdown"].read_text()
    assert text.count("\n| ") == 7 + 1  # header + one row per joint
    assert f"{result['max_abs'][1]:.3e}" in text


def test_validate_rejects_robots_without_seven_joints(tmp_path):
    class Six:
        manifest = {"dof": 6, "gravity_symbols": [], "robot": "six"}

    class Robot:
        name = "six"

    with pytest.raises(ValueError, match="7 joints"):
        validate(Robot(), None, np.zeros(60), np.zeros(1), np.zeros(1), tmp_path, model=Six())
