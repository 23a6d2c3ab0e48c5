"""Identification (eq. 11): from torques of known parameters computed by Pinocchio (an
independent oracle), the identified coefficients predict held-out torques, gravity and
inertia matrices exactly; non-exciting data are flagged; the CLI writes what extract reads."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT
from oracles import pinocchio_arm
from oracles.arm import Arm
from oracles.random_params import random_parameters
from synthetic import fourier, rigid_torques, signals

from dyngen.description import load_robot
from dyngen.extraction.targets import target
from dyngen.generate import build
from dyngen.identification import identify, identified_yaml
from dyngen.runtime import load

LWR = ROOT / "examples" / "lwr.yaml"


@pytest.fixture(scope="module")
def setup():
    model = load(ROOT / "generated" / "lwr")
    arm = Arm.from_yaml(LWR)
    p = random_parameters(7, seed=3)
    return model, arm, p


def trajectory(arm, p, seed, duration=6.0):
    t, at = fourier(7, seed, duration=duration, rate=100.0)
    q, qd, qdd = at(t)
    return signals(f"traj{seed}", t, q, qd, qdd, rigid_torques(arm, p, q, qd, qdd))


def test_full_coefficients_predict_held_out_torques(setup):
    model, arm, p = setup
    est = identify(model, [trajectory(arm, p, 1)], "full")
    held = trajectory(arm, p, 2)
    predicted = np.einsum("tjk,k->tj", model.batch("regressor", held.q, held.qd, held.qdd), est.values)
    assert np.max(np.abs(predicted - held.tau)) < 1e-8 * np.max(np.abs(held.tau))
    assert est.unexcited == [] and est.residual_rms < 1e-9
    assert np.all(est.std < 1e-8 * np.maximum(1.0, np.abs(est.values)))  # exact data: no spread
    assert 1 < est.condition < 1e6


def test_gravity_and_inertia_from_fri_like_samples(setup):
    """g(q) and M(q) samples (the paper's FRI case, eqs. 9-10), from Pinocchio."""
    model, arm, p = setup
    rng = np.random.default_rng(5)
    q = rng.uniform(-2, 2, (60, 7))
    zeros = np.zeros_like(q)
    g = np.array([pinocchio_arm.gravity(arm, p, x) for x in q])
    est_g = identify(model, [signals("static", np.arange(60.0), q, zeros, zeros, g)], "gravity")
    q_test = rng.uniform(-2, 2, (20, 7))
    g_test = np.array([pinocchio_arm.gravity(arm, p, x) for x in q_test])
    assert np.allclose(model.batch("regressor_gravity", q_test) @ est_g.values, g_test, atol=1e-9)
    iu = np.triu_indices(7)
    M = np.array([pinocchio_arm.mass_matrix(arm, p, x)[iu] for x in q])
    sig = signals("fri", np.arange(60.0), q, zeros, zeros, None)
    sig.extra = {name: M[:, k] for k, name in enumerate(model.manifest["stacked_inertia_order"])}
    est_m = identify(model, [sig], "inertia")
    M_test = np.array([pinocchio_arm.mass_matrix(arm, p, x)[iu] for x in q_test])
    assert np.allclose(model.batch("regressor_inertia", q_test) @ est_m.values, M_test, atol=1e-9)


def test_static_data_do_not_excite_inertial_coefficients(setup):
    model, arm, p = setup
    rng = np.random.default_rng(6)
    q = rng.uniform(-2, 2, (80, 7))
    zeros = np.zeros_like(q)
    tau = np.array([pinocchio_arm.gravity(arm, p, x) for x in q])
    est = identify(model, [signals("static", np.arange(80.0), q, zeros, zeros, tau)], "full")
    assert len(est.unexcited) == 43 - 12  # only the gravity directions are seen
    assert len(est.warnings()) == 31 and all("do not excite" in w for w in est.warnings())
    assert np.all(np.isinf(est.std[est.unexcited]))


def test_written_yaml_is_what_extract_reads(setup, tmp_path):
    """The identified block maps into dyngen's own basis exactly (targets W = identity)."""
    model, arm, p = setup
    est = identify(model, [trajectory(arm, p, 1, duration=3.0)], "full")
    robot_text = LWR.read_text().split("identified:")[0]
    block = identified_yaml("lwr", {"full": est}, ["traj1"], "as recorded")
    (tmp_path / "robot.yaml").write_text(robot_text + "\n".join(block.splitlines()[4:]) + "\n")
    robot = load_robot(tmp_path / "robot.yaml")
    bases, _ = build(robot)
    t = target(robot, bases["full"], "full")
    assert np.array_equal(t.W, np.eye(43)) and np.allclose(t.v, est.values)


def test_identify_cli(setup, tmp_path):
    model, arm, p = setup
    s = trajectory(arm, p, 4, duration=3.0)
    header = ["t"] + [f"q{j}" for j in range(1, 8)] + [f"tau{j}" for j in range(1, 8)]
    rows = np.column_stack([s.t, s.q, s.tau])
    csv = tmp_path / "run.csv"
    np.savetxt(csv, rows, delimiter=",", header=",".join(header), comments="")
    out = tmp_path / "id.yaml"
    r = subprocess.run([sys.executable, "-m", "dyngen", "identify", LWR, "--ols", "--data", csv, "--differentiate",
                        "--model", ROOT / "generated" / "lwr", "-o", out], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "condition number" in r.stdout and out.exists() and out.read_text().count("coefficient:") == 43
    bad = tmp_path / "bad.csv"
    bad.write_text(csv.read_text().replace("tau7", "tau8", 1))
    r = subprocess.run([sys.executable, "-m", "dyngen", "identify", LWR, "--data", bad, "--model",
                        ROOT / "generated" / "lwr", "-o", tmp_path / "no.yaml"], capture_output=True, text=True)
    assert r.returncode != 0 and r.stderr.strip().count("\n") == 0
    assert "bad.csv: line 1 (header): the robot has 7 joints but the file has tau8" in r.stderr
    assert not (tmp_path / "no.yaml").exists()
