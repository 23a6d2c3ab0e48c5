"""The real-arm example (examples/lwr4-real, three KUKA LWR4+ runs): the residual the
diagnosis starts from equals Pinocchio's Newton-Euler residual on the same samples, the
selected effects shrink the residual of held-out measurement 3 on every joint they are
claimed for, and the steady biases the data's README reports are found as sensor offsets."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from oracles import pinocchio_arm
from oracles.arm import Arm

from dyngen.data import condition, read_recording
from dyngen.data.parameters_file import read_link_parameters
from dyngen.description import load_robot
from dyngen.diagnosis import diagnose
from dyngen.runtime import load

HERE = ROOT / "examples" / "lwr4-real"
LWR = ROOT / "examples" / "lwr.yaml"


@pytest.fixture(scope="module")
def result():
    robot = load_robot(LWR)
    p = read_link_parameters(ROOT / "examples" / "lwr_paper_solution.yaml", 7)
    fit = condition(read_recording(HERE / "measurement_1.csv", 7))
    held = condition(read_recording(HERE / "measurement_3.csv", 7))
    return diagnose(robot, load(ROOT / "generated" / "lwr"), p, [fit], [held]), p, held


def test_before_rms_matches_pinocchio(result):
    d, p, held = result
    arm = Arm.from_yaml(LWR)
    model, data = pinocchio_arm.build(arm, p)
    import pinocchio as pin

    tau = np.array([pin.rnea(model, data, q, v, a).copy() for q, v, a in zip(held.q, held.qd, held.qdd)])
    expected = np.sqrt(np.mean((held.tau - tau) ** 2, axis=0))
    assert np.allclose(d.rms_before, expected, rtol=1e-9)
    assert 0.25 < min(expected) and max(expected) < 1.3  # the data README: 0.3-1.3 Nm per joint


def test_effects_shrink_held_out_residual_where_claimed(result):
    d, _, _ = result
    claimed = {j for e in d.selected for j in e["joints"]}
    assert claimed >= {1, 2, 3, 4, 5, 6}
    for j in claimed:
        assert d.rms_after[j - 1] < 0.5 * d.rms_before[j - 1], j
    for e in d.selected:  # each effect on its own helps its joints on held-out data
        for j in e["joints"]:
            assert e["rms_after"][j - 1] < e["rms_before"][j - 1]


def test_steady_biases_found_as_offsets(result):
    """The data README: about +0.9 Nm on joint 1, -0.7 Nm on joint 5, +0.6 Nm on joint 6."""
    d, _, _ = result
    offsets = {e["joints"][0]: e["values"]["b"] for e in d.selected if e["effect"] == "offset"}
    for joint, bias in ((1, 0.9), (5, -0.7), (6, 0.6)):
        assert offsets[joint] == pytest.approx(bias, abs=0.15)
