"""Cross-checks of the two independent oracles (numeric Lagrangian vs Pinocchio).

If these agree on arms of both DH conventions, with prismatic joints, theta offsets and a
tilted gravity, both are trustworthy references for the generated code.
"""
import math

import numpy as np
import pytest

from oracles import lagrangian as lag
from oracles import pinocchio_arm as pa
from oracles.arm import Arm, evaluate, nominal_parameters
from oracles.random_params import is_consistent, random_parameters

PI = math.pi
G = np.array([0.0, 0.0, -9.81])

# KUKA LWR IV+, standard DH (/work/shared/reference/lwr.md)
LWR = Arm("standard", (
    ("revolute", 0, PI / 2, 0, 0),
    ("revolute", 0, -PI / 2, 0, 0),
    ("revolute", 0, -PI / 2, 0.4, 0),
    ("revolute", 0, PI / 2, 0, 0),
    ("revolute", 0, PI / 2, 0.39, 0),
    ("revolute", 0, -PI / 2, 0, 0),
    ("revolute", 0, 0, 0, 0),
), G)

# Franka-Panda-like, modified DH, non-zero a and d, mixed alphas
PANDA = Arm("modified", (
    ("revolute", 0, 0, 0.333, 0),
    ("revolute", 0, -PI / 2, 0, 0),
    ("revolute", 0, PI / 2, 0.316, 0),
    ("revolute", 0.0825, PI / 2, 0, 0),
    ("revolute", -0.0825, -PI / 2, 0.384, 0),
    ("revolute", 0, PI / 2, 0, 0),
    ("revolute", 0.088, PI / 2, 0, 0),
), G)

# Stanford-like RRPRRR, standard DH, theta offsets, prismatic joint with constant theta and d0
STANFORD = Arm("standard", (
    ("revolute", 0, -PI / 2, 0.412, 0.1),
    ("revolute", 0, PI / 2, 0.154, -PI / 2),
    ("prismatic", 0.05, 0, 0.2, -PI / 2),
    ("revolute", 0, -PI / 2, 0, 0.4),
    ("revolute", 0, PI / 2, 0, 0),
    ("revolute", 0, 0, 0.263, 0.2),
), G)

# 3 joints, modified DH, theta offsets everywhere, a prismatic joint, tilted gravity
TILTED = Arm("modified", (
    ("revolute", 0, 0, 0.3, 0.5),
    ("prismatic", 0.2, -PI / 2, 0.1, 0.7),
    ("revolute", 0.3, PI / 3, 0.05, -1.1),
), np.array([1.2, -2.0, -9.5]))

# the same 3-joint arm in standard DH, to cover a standard prismatic joint with tilted gravity
TILTED_STD = Arm("standard", TILTED.joints, TILTED.gravity)

ARMS = {"lwr": LWR, "panda": PANDA, "stanford": STANFORD, "tilted": TILTED, "tilted_std": TILTED_STD}
N_STATES = 20


def states(arm, seed, n=N_STATES):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        q = np.array([rng.uniform(-PI, PI) if j[0] == "revolute" else rng.uniform(-0.5, 0.5)
                      for j in arm.joints])
        yield q, rng.standard_normal(arm.n) * 2, rng.standard_normal(arm.n) * 3


def rel_err(a, b):
    return np.max(np.abs(a - b)) / max(1.0, np.max(np.abs(b)))


@pytest.fixture(params=list(ARMS), scope="module")
def case(request):
    arm = ARMS[request.param]
    p = random_parameters(arm.n, seed=len(request.param))
    return request.param, arm, p


def test_random_parameters_are_consistent(case):
    _, _, p = case
    assert is_consistent(p)
    P = p.reshape(-1, 10)
    assert np.all((P[:, 0] >= 0.5) & (P[:, 0] <= 5)) and np.all(np.abs(P[:, 1:4]) <= 0.1)


def test_forward_kinematics_agree(case):
    _, arm, _ = case
    for q, _, _ in states(arm, 1, 5):
        lag_frames = lag.forward_kinematics(arm, q)[1:]
        for T1, T2 in zip(lag_frames, pa.frame_poses(arm, q)):
            assert np.allclose(T1, T2, rtol=0, atol=1e-12)


def test_mass_matrix_and_gravity_agree(case):
    _, arm, p = case
    for q, _, _ in states(arm, 2):
        M = lag.mass_matrix(arm, q, p)
        assert rel_err(M, pa.mass_matrix(arm, p, q)) < 1e-10
        assert np.allclose(M, M.T, rtol=0, atol=1e-14)
        assert np.linalg.eigvalsh(M)[0] > 0
        assert rel_err(lag.gravity(arm, q, p), pa.gravity(arm, p, q)) < 1e-10


def test_inverse_dynamics_agree(case):
    _, arm, p = case
    for q, qd, qdd in states(arm, 3):
        tau = pa.rnea(arm, p, q, qd, qdd)
        assert rel_err(lag.inverse_dynamics(arm, q, qd, qdd, p), tau) < 1e-8
        # the velocity term alone, to make sure c is not hidden by M qdd + g
        c_pin = pa.rnea(arm, p, q, qd, np.zeros(arm.n)) - pa.gravity(arm, p, q)
        assert rel_err(lag.coriolis(arm, q, qd, p), c_pin) < 1e-9


def test_gravity_is_gradient_of_potential(case):
    _, arm, p = case
    h = 1e-5
    for q, _, _ in states(arm, 4, 5):
        E = np.eye(arm.n)
        fd = np.array([(lag.potential_energy(arm, q + h * E[k], p)
                        - lag.potential_energy(arm, q - h * E[k], p)) / (2 * h) for k in range(arm.n)])
        assert rel_err(fd, lag.gravity(arm, q, p)) < 1e-8


def test_christoffel_properties(case):
    # c = (dM/dt) qd - 1/2 d/dq (qd^T M qd), and Mdot - 2C skew-symmetric (C_ij = sum_k Gamma_ijk qd_k)
    _, arm, p = case
    for q, qd, _ in states(arm, 5, 3):
        dM = lag.mass_matrix_derivatives(arm, q, p)
        Mdot = np.einsum("kij,k->ij", dM, qd)
        c = Mdot @ qd - 0.5 * np.einsum("kij,i,j->k", dM, qd, qd)
        assert rel_err(lag.coriolis(arm, q, qd, p), c) < 1e-12
        C = np.einsum("ijk,k->ij", lag.christoffel(arm, q, p), qd)
        S = Mdot - 2 * C
        assert np.allclose(S, -S.T, rtol=0, atol=1e-12)


def test_pinocchio_regressor_reproduces_rnea(case):
    _, arm, p = case
    model, _ = pa.build(arm, p)
    phi = pa.pinocchio_parameters(model)
    s = lag.standard_from_dynamic(p)
    for q, qd, qdd in states(arm, 6, 10):
        tau = pa.rnea(arm, p, q, qd, qdd)
        assert rel_err(pa.joint_torque_regressor(arm, q, qd, qdd) @ phi, tau) < 1e-10
        # the regressor in the conventions' standard parameters (frame i)
        assert rel_err(pa.standard_regressor(arm, q, qd, qdd) @ s, tau) < 1e-10


def test_standard_dynamic_round_trip(case):
    _, arm, p = case
    s = lag.standard_from_dynamic(p)
    assert np.allclose(lag.dynamic_from_standard(s), p, rtol=0, atol=1e-14)
    m, c = p[0], p[1:4]
    assert np.allclose(s[1:4], m * c)
    # XX = Ixx + m (cy^2 + cz^2), XY = Ixy - m cx cy (matrix-entry convention)
    assert np.isclose(s[4], p[4] + m * (c[1] ** 2 + c[2] ** 2))
    assert np.isclose(s[5], p[5] - m * c[0] * c[1])


def test_stacked_upper():
    M = np.arange(9.0).reshape(3, 3)
    assert list(lag.stacked_upper(M)) == [0, 1, 2, 4, 5, 8]


@pytest.mark.parametrize("kind, rank", [("gravity", 12), ("inertia", 39), ("full", 43)])
def test_lwr_regressor_ranks(kind, rank):
    assert pa.regressor_rank(LWR, kind, n_samples=30, seed=7) == rank


def test_inertia_regressor_rows_are_stacked_mass_matrix():
    # the 'inertia' stack times the parameters is the stacked upper triangle of M
    arm, p = STANFORD, random_parameters(STANFORD.n, seed=11)
    s = lag.standard_from_dynamic(p)
    Y = pa.sampled_regressor(arm, "inertia", n_samples=2, seed=3, basis="standard")
    rng = np.random.default_rng(3)
    expected = np.concatenate([lag.stacked_upper(lag.mass_matrix(arm, pa._random_q(arm, rng), p))
                               for _ in range(2)])
    assert rel_err(Y @ s, expected) < 1e-10


def test_yaml_reading(tmp_path):
    text = """
name: lwr
dh: standard
gravity: [0, 0, -g]
joints:
  - {type: revolute, a: 0, alpha: pi/2, d: 0, theta: 0}
  - {type: revolute, a: 0, alpha: -pi/2, d: 0, theta: 0, limits: {lower: -2, upper: 2}}
  - {type: prismatic, a: 0.1, alpha: "-(pi/2)", d: 0.4, theta: 2*pi/3}
parameters:
  nominal:
    - {m: 2.7, c: [0.1, 0.2, 0.3], I: [1, 2, 3, 4, 5, 6]}
    - {m: 1, c: [0, 0, 0], I: [1, 0, 0, 1, 0, 1]}
    - {m: 0.5, c: [0, -0.1, 0], I: [0.1, 0, 0, 0.2, 0, 0.3]}
"""
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    arm = Arm.from_yaml(path, symbols={"g": 9.81})
    assert arm.convention == "standard"
    assert arm.joints[2] == ("prismatic", 0.1, -PI / 2, 0.4, 2 * PI / 3)
    assert np.allclose(arm.gravity, G)
    p = nominal_parameters(path)
    assert p.shape == (30,) and p[0] == 2.7 and list(p[4:10]) == [1, 2, 3, 4, 5, 6]


@pytest.mark.parametrize("bad", ["__import__('os')", "pi**2", "e", "sin(1)", "[1]", "True"])
def test_evaluator_rejects_code(bad):
    with pytest.raises((ValueError, SyntaxError)):
        evaluate(bad)


def test_evaluator_values():
    assert evaluate("pi/2") == PI / 2
    assert evaluate("-pi/2") == -PI / 2
    assert evaluate("(1 + 2) * pi / 3") == pytest.approx(PI)
    assert evaluate(0.25) == 0.25
