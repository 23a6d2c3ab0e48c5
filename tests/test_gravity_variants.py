"""Gravity comes from the YAML: a tilted or a symbolic gravity gives other coefficient sets."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import ROOT, build_arm
from oracles import lagrangian as lag
from oracles import pinocchio_arm as pin_arm
from oracles.arm import Arm
from oracles.random_params import random_parameters

LWR_TEXT = (ROOT / "examples" / "lwr.yaml").read_text()


def variant(tmp_path, gravity_line: str, gravity_values=None):
    text = LWR_TEXT.replace("gravity: [0, 0, -9.81]", gravity_line)
    assert text != LWR_TEXT
    path = tmp_path / "lwr.yaml"
    path.write_text(text)
    return build_arm(path, tmp_path, gravity_values)


def numerical_rank(Y, rtol=1e-9):
    sv = np.linalg.svd(Y, compute_uv=False)
    return int(np.sum(sv > rtol * sv[0]))


@pytest.fixture(scope="module")
def tilted(tmp_path_factory):
    return variant(tmp_path_factory.mktemp("tilted"), "gravity: [1.2, -0.5, -9.7]")


@pytest.fixture(scope="module")
def symbolic(tmp_path_factory):
    return variant(tmp_path_factory.mktemp("symbolic"), "gravity: [gx, gy, gz]", {"gx": 0.0, "gy": 0.0, "gz": -9.81})


def test_tilted_gravity_changes_the_gravity_coefficients(tilted):
    rank = tilted.bases["gravity"].rank
    assert rank != 12  # joint 1 now lifts link masses: link 1 parameters enter
    assert rank == pin_arm.regressor_rank(tilted.arm, "gravity", n_samples=40, seed=1)
    assert tilted.bases["inertia"].rank == 39  # the inertia matrix does not see gravity


def test_tilted_gravity_c_matches_lagrangian(tilted):
    rng = np.random.default_rng(0)
    p = random_parameters(7, seed=2)
    pi_g = tilted.c("pi_gravity", p)
    for _ in range(50):
        q = rng.uniform(-np.pi, np.pi, 7)
        g = lag.gravity(tilted.arm, q, p)
        assert np.allclose(tilted.c("regressor_gravity", q) @ pi_g, g, rtol=0, atol=1e-9 * max(1, abs(g).max()))


def test_symbolic_gravity_is_an_input_and_spans_all_directions(symbolic):
    assert symbolic.c.manifest["gravity_symbols"] == ["gx", "gy", "gz"]
    rng = np.random.default_rng(3)
    arms = [dataclasses.replace(symbolic.arm, gravity=rng.standard_normal(3) * 9.81) for _ in range(6)]
    stacked = np.vstack([pin_arm.sampled_regressor(a, "gravity", n_samples=10, seed=k) for k, a in enumerate(arms)])
    rank = symbolic.bases["gravity"].rank
    assert rank == numerical_rank(stacked)
    assert rank > 12  # more than the upright arm (eq. 8); a generic tilt needs as many
    p = random_parameters(7, seed=4)
    s = symbolic.c("standard_from_dynamic", p)
    pi_g = symbolic.c("pi_gravity", p)
    for arm in arms:
        q, qd, qdd = rng.uniform(-np.pi, np.pi, 7), rng.uniform(-2, 2, 7), rng.uniform(-2, 2, 7)
        g = lag.gravity(arm, q, p)
        assert np.allclose(symbolic.c("regressor_gravity", q, arm.gravity) @ pi_g, g, rtol=1e-9, atol=1e-9)
        tau = lag.inverse_dynamics(arm, q, qd, qdd, p)
        assert np.allclose(symbolic.c("rnea", q, qd, qdd, s, arm.gravity), tau, rtol=1e-9, atol=1e-9)


def test_oracle_reads_symbolic_gravity(symbolic, tmp_path):
    arm = Arm.from_yaml(symbolic.yaml, symbols={"gx": 0.0, "gy": 0.0, "gz": -9.81})
    assert np.allclose(arm.gravity, [0, 0, -9.81])
