"""The diagnosis on arms other than the LWR (Panda, Stanford arm with its prismatic joint, UR5,
PUMA 560), from positions as a 20-bit encoder records them (no qd, qdd columns), 500 Hz:
torques from Pinocchio's Newton-Euler (tests/oracles, no dyngen code) with a sign-law Coulomb
friction on joint 2 and a sensor offset on joint 1 injected. It must name exactly those two,
recover them within 10 %, and do as well as the simple model on every joint of a different test
trajectory (within 3 %: at the noise floor), far better on the friction joint."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from oracles.arm import Arm
from oracles.random_params import random_parameters
from synthetic import fourier, noisy, rigid_torques

from dyngen.data import condition
from dyngen.data.recording import Recording
from dyngen.description import load_robot
from dyngen.diagnosis import diagnose
from dyngen.generate import generate
from dyngen.progress import Progress
from dyngen.runtime import load

FC, OFFSET, NOISE = 0.8, 0.5, 0.05


def encoder_recording(name, arm, p, seed, rng):
    t, at = fourier(p.size // 10, seed, duration=20.0, rate=500.0)
    q, qd, qdd = at(t)
    tau = rigid_torques(arm, p, q, qd, qdd)
    tau[:, 1] += FC * np.sign(qd[:, 1])
    tau[:, 0] += OFFSET
    step = 2 * np.pi / 2 ** 20
    encoded = np.round((q + 1e-5 * rng.standard_normal(q.shape)) / step) * step
    return condition(Recording(name, t, encoded, noisy(tau, NOISE, seed)))


@pytest.mark.parametrize("name", ["panda", "stanford", "ur5", "puma560"])
def test_friction_and_offset_on_other_arms(name):
    path = ROOT / "examples" / f"{name}.yaml"
    robot, arm = load_robot(path), Arm.from_yaml(path)
    model = load(generate(robot, None, Progress(quiet=True)).folder)
    p = random_parameters(robot.dof, seed=3)
    rng = np.random.default_rng(0)
    fit, test = (encoder_recording(k, arm, p, seed, rng) for k, seed in (("fit", 11), ("test", 12)))
    d = diagnose(robot, model, p, [fit], None, test=[test])
    assert sorted((e.effect, e.joints) for e in d.selected) == [("coulomb", (2,)), ("offset", (1,))]
    values = {e.effect: e.values for e in d.selected}
    assert values["coulomb"]["Fc"] == pytest.approx(FC, rel=0.1)
    assert values["offset"]["b"] == pytest.approx(OFFSET, rel=0.1)
    # Where both models hold the same offset, their test RMS differ by estimation noise only.
    assert all(a <= 1.03 * s for a, s in zip(d.rms_after, d.rms_simple)), (d.rms_after, d.rms_simple)
    assert d.rms_after[1] < 0.7 * d.rms_simple[1]  # the friction joint: the sign law the simple model smooths
