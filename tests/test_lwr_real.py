"""The real-arm example (examples/lwr4-real, three KUKA LWR4+ runs): the residual the
diagnosis starts from equals Pinocchio's Newton-Euler residual on the same samples; with the
three roles (fit m1 or m2, selection on blocks of it, test m3, a different and faster
trajectory) the final model beats the simple model (per joint offset + Coulomb + viscous fitted
on the same fit data) on the test recording; testing on m2, which repeats m1's trajectory, is
flagged; and the steady biases the data's README reports are found as sensor offsets."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from oracles import pinocchio_arm
from oracles.arm import Arm

from dyngen.data import condition, read_recording
from dyngen.data.parameters_file import read_link_parameters
from dyngen.description import load_robot
from dyngen.diagnosis import Options, diagnose
from dyngen.runtime import load

HERE = ROOT / "examples" / "lwr4-real"
LWR = ROOT / "examples" / "lwr.yaml"
# The simple model's test RMS on m3 when fitted on m1 (docs: shared reference measured-data.md),
# computed here independently of dyngen's baseline module.
SIMPLE_M1_M3 = [0.755, 0.404, 0.237, 0.411, 0.264, 0.186, 0.259]


def recording(k):
    return condition(read_recording(HERE / f"measurement_{k}.csv", 7))


@pytest.fixture(scope="module")
def setup():
    return load_robot(LWR), load(ROOT / "generated" / "lwr"), read_link_parameters(
        ROOT / "examples" / "lwr_paper_solution.yaml", 7)


@pytest.fixture(scope="module")
def m1_m3(setup):
    robot, model, p = setup
    return diagnose(robot, model, p, [recording(1)], None, test=[recording(3)])


def test_before_rms_matches_pinocchio(setup, m1_m3):
    robot, model, p = setup
    held = recording(3)
    arm = Arm.from_yaml(LWR)
    pm, data = pinocchio_arm.build(arm, p)
    import pinocchio as pin

    tau = np.array([pin.rnea(pm, data, q, v, a).copy() for q, v, a in zip(held.q, held.qd, held.qdd)])
    expected = np.sqrt(np.mean((held.tau - tau) ** 2, axis=0))
    assert np.allclose(m1_m3.rms_before, expected, rtol=1e-9)
    assert 0.25 < min(expected) and max(expected) < 1.3  # the data README: 0.3-1.3 Nm per joint


def test_simple_model_is_the_published_baseline(setup, m1_m3):
    """b + Fc tanh(qd/0.02) + Fv qd per joint, by plain least squares here (numpy), fitted on
    all of m1: the diagnosis reports the same test RMS beside its own."""
    robot, model, p = setup
    s = model("standard_from_dynamic", p)
    fit, test = recording(1), recording(3)
    rms = []
    for j in range(7):
        def A(g):
            return np.column_stack([np.ones(g.t.size), np.tanh(g.qd[:, j] / 0.02), g.qd[:, j]])

        r_fit = fit.tau[:, j] - model.batch("rnea", fit.q, fit.qd, fit.qdd, s)[:, j]
        r_test = test.tau[:, j] - model.batch("rnea", test.q, test.qd, test.qdd, s)[:, j]
        x = np.linalg.lstsq(A(fit), r_fit, rcond=None)[0]
        rms.append(np.sqrt(np.mean((r_test - A(test) @ x) ** 2)))
    assert np.allclose(rms, SIMPLE_M1_M3, atol=5e-4)
    assert np.allclose(m1_m3.rms_simple, rms, rtol=1e-6)


@pytest.fixture(scope="module")
def m2_m3(setup):
    robot, model, p = setup
    return diagnose(robot, model, p, [recording(2)], None, test=[recording(3)])


@pytest.mark.parametrize("fit", [[1], [2], [1, 2]], ids=["m1", "m2", "m1+m2"])
def test_at_most_the_simple_model_on_every_joint(setup, m1_m3, m2_m3, fit):
    robot, model, p = setup
    given = {(1,): m1_m3, (2,): m2_m3}
    d = given.get(tuple(fit)) or diagnose(robot, model, p, [recording(k) for k in fit], None, test=[recording(3)])
    assert all(a <= s + 1e-9 for a, s in zip(d.rms_after, d.rms_simple)), (d.rms_after, d.rms_simple)
    if fit == [1, 2]:
        assert np.mean(d.rms_after) <= 0.25


def test_m2_to_m3_mean_within_the_issue_bar(m2_m3):
    assert np.mean(m2_m3.rms_after) <= 0.25


@pytest.mark.parametrize("seconds", [1.5, 2.5, 3.0])
def test_m1_to_m3_does_not_hinge_on_how_the_fit_data_are_cut(setup, m1_m3, seconds):
    """Other selection block lengths than the default 2 s: the mean stays near the default's and
    within the issue's 0.25 Nm, and no joint ends more than 10 % above the simple model. With
    selection judged on one cut, 2.5-s blocks gave joint 2 0.567 Nm against the simple model's
    0.404; with the groups shifted by one block, joints 4, 5, 7 were worse and the mean 0.361
    (docs/measured-data.md). Joint 5, whose friction falls with speed, may stay a few per cent
    above the simple model: the fit data cannot tell the two apart."""
    robot, model, p = setup
    d = diagnose(robot, model, p, [recording(1)], None, Options(block_seconds=seconds), test=[recording(3)])
    after, simple = np.array(d.rms_after), np.array(d.rms_simple)
    assert np.mean(after) <= min(0.25, np.mean(m1_m3.rms_after) + 0.02)
    assert np.all(after <= 1.1 * simple), (after, simple)


def test_m1_to_m3(m1_m3):
    """A mean of at most 0.25 Nm; at the joint velocities m1 covered, at most the simple model's
    test RMS on every joint; and the report says that the test speeds exceed the fit data's
    (m3 moves joint 4 55 % faster). On joint 5 the effects (Coulomb and an offset) and the
    simple model are within 1 % on m1's selection data, so the simple model predicts there
    (joints.TIED) and the effects stay findings; over all of m3 the effects alone would leave
    0.284 Nm against the simple model's 0.264: its friction falls with speed (a negative
    viscous value), which m1 shows too weakly to choose on (docs/measured-data.md)."""
    from dyngen.diagnosis import joints

    after, simple = np.array(m1_m3.rms_after), np.array(m1_m3.rms_simple)
    w = m1_m3.within_fit_speeds
    assert np.all(np.array(w["rms_after"]) <= np.array(w["rms_simple"]) + 1e-9), w
    assert np.mean(after) <= 0.25
    assert any("faster than any fit data" in w and "4 (" in w for w in m1_m3.warnings)
    assert m1_m3.joint_models[4] == joints.TIED
    assert any(e.effect == "coulomb" and e.joints == (5,) for e in m1_m3.selected)


def test_the_terminal_says_where_the_simple_model_is_better(setup):
    """With 1.5-s selection blocks, a position ripple on m1's joint 5 gains enough on its
    selection data to predict the joint, and on m3 ends above the simple model: that joint is
    named with both figures, and with both at the velocities the fit data covered (where the
    final model is the better one)."""
    from dyngen.diagnosis.report_text import summary_lines

    robot, model, p = setup
    d = diagnose(robot, model, p, [recording(1)], None, Options(block_seconds=1.5), test=[recording(3)])
    line = next(x for x in summary_lines(d) if "worse than the simple model" in x)
    after, simple = d.rms_after[4], d.rms_simple[4]
    assert after > simple
    assert f"joint(s) 5 ({after:.3f} vs {simple:.3f})" in line
    w = d.within_fit_speeds
    assert f"covered {w['rms_after'][4]:.3f} vs {w['rms_simple'][4]:.3f}" in line
    assert not any(f"joint(s) {j}" in line for j in (1, 2, 3, 4, 6, 7))


def test_share_of_test_samples_beyond_the_fit_speeds(m1_m3):
    """within_fit_speeds.share_beyond against numpy on the recordings: m3 samples whose joint
    velocity lies outside the range m1's velocities span (m1's filter start-up trimmed; the
    diagnosis also leaves out the filter's reach around block cuts, hence the tolerance)."""
    fit, test = recording(1), recording(3)
    qd_fit, qd_test = fit.qd[fit.inner()], test.qd[test.inner()]
    outside = (qd_test < qd_fit.min(axis=0)) | (qd_test > qd_fit.max(axis=0))
    assert np.allclose(m1_m3.within_fit_speeds["share_beyond"], outside.mean(axis=0), atol=0.01)
    assert 0.5 < outside.mean() < 0.8  # m3 is the faster motion (its README)


def test_repeated_trajectory_is_flagged(setup, m1_m3):
    robot, model, p = setup
    d = diagnose(robot, model, p, [recording(1)], None, test=[recording(2)])
    assert any("repeats the trajectory of measurement_1.csv" in w for w in d.warnings), d.warnings
    assert not any("repeats" in w for w in m1_m3.warnings)


def test_steady_biases_found_as_offsets(m1_m3):
    """The data README: about +0.9 Nm on joint 1 (and a bias on joint 6, here with friction)."""
    offsets = {e.joints[0]: e.values["b"] for e in m1_m3.selected if e.effect == "offset"}
    assert offsets[1] == pytest.approx(0.9, abs=0.15)


def test_positions_alone_give_the_residual_of_the_recorded_velocities(setup):
    """The recordings' stamps jitter around the controller's 5 ms clock: from positions alone
    (qd, qdd columns dropped), dyngen must differentiate over the clock, and the nominal
    residual on m3 then matches the one from the controller's own qd, qdd (Pinocchio's torques
    from the recorded columns are the reference); over the stamps joint 1 would read 1.54 Nm."""
    import dataclasses

    import pinocchio as pin

    robot, model, p = setup
    raw = read_recording(HERE / "measurement_3.csv", 7)
    alone = condition(dataclasses.replace(raw, qd=None, qdd=None))
    assert any("jitter" in w for w in alone.warnings)
    pm, data = pinocchio_arm.build(Arm.from_yaml(LWR), p)

    def rms(sig):
        k = sig.inner()
        tau = np.array([pin.rnea(pm, data, q, v, a).copy() for q, v, a in zip(sig.q[k], sig.qd[k], sig.qdd[k])])
        return np.sqrt(np.mean((sig.tau[k] - tau) ** 2, axis=0))

    assert np.allclose(rms(alone), rms(condition(raw)), rtol=0.05)
