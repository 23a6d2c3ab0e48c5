"""Rounded constants (pi/2 written 1.5708): snapped, the counts equal the rank of Pinocchio's
regressor on the exact arm and the torques equal Pinocchio's on the exact URDF to 1e-9 (and on
the rounded one within the snap's effect); with --no-snap the rounded numbers are kept exactly."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from cbuild import compile_folder
from test_urdf import DATA, configuration, numerical_rank, pinocchio_chain, rel_err

from dyngen.atomic import write_folder
from dyngen.description.urdf import load_urdf
from dyngen.generate import build

ROUNDED = "1.5708"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("snap")
    text = (DATA / "ur5_robot.urdf").read_text()
    assert text.count("1.57079632679") >= 2
    (folder / "rounded.urdf").write_text(text.replace("1.57079632679", ROUNDED))
    (folder / "exact.urdf").write_text(text.replace("1.57079632679", repr(np.pi / 2)))
    kinova = (DATA / "kinova.urdf").read_text()
    (folder / "kinova_rounded.urdf").write_text(kinova.replace("1.57079632679", ROUNDED).replace("3.14159265359",
                                                                                                  "3.1416"))
    return folder


def generated(path, folder, snap):
    robot = load_urdf(path, snap=snap)
    bases, emitted = build(robot)
    write_folder(folder / robot.name, emitted.files)
    return robot, bases, compile_folder(folder / robot.name, folder / "build")


def worst_error(c, robot, model, data, states=20):
    rng = np.random.default_rng(4)
    s = c("standard_from_dynamic", np.concatenate([v.as_tuple() for v in robot.nominal]))
    n, worst = robot.dof, 0.0
    for _ in range(states):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)
        worst = max(worst, rel_err(c("rnea", q, qd, qdd, s), pin.rnea(model, data, configuration(model, q), qd, qdd)))
    return worst


def test_snapped_counts_and_torques(files):
    robot, bases, c = generated(files / "rounded.urdf", files / "snapped", snap=True)
    assert [(x.joint, x.field, x.before, x.after) for x in robot.snaps] == [
        ("shoulder_lift_joint", "origin.rpy[1]", ROUNDED, "pi/2"), ("wrist_1_joint", "origin.rpy[1]", ROUNDED, "pi/2"),
        # the tool frames fixed beyond the tip (massless here, but lumped and so snapped too)
        ("ee_fixed_joint", "origin.rpy[2]", ROUNDED, "pi/2"),
        ("wrist_3_link-tool0_fixed_joint", "origin.rpy[0]", "-" + ROUNDED, "-pi/2")]
    exact_model, exact_data = pinocchio_chain(files / "exact.urdf", robot.links)
    assert bases["gravity"].rank == numerical_rank(exact_model, exact_data, "gravity", np.random.default_rng(1))
    assert bases["full"].rank == numerical_rank(exact_model, exact_data, "full", np.random.default_rng(2))
    assert worst_error(c, robot, exact_model, exact_data) < 1e-9
    rounded_model, rounded_data = pinocchio_chain(files / "rounded.urdf", robot.links)
    assert 1e-9 < worst_error(c, robot, rounded_model, rounded_data) < 1e-4  # the snap's effect: ~4e-6 rad


def test_no_snap_keeps_the_rounded_arm(files):
    """The Kinova arm with pi written 3.1416 and pi/2 1.5708: kept, its twists are no longer right
    angles and the counts grow to the rounded arm's rank (snapped, they are the exact arm's)."""
    path = files / "kinova_rounded.urdf"
    robot, bases, c = generated(path, files / "kept", snap=False)
    assert robot.snaps == ()
    model, data = pinocchio_chain(path, robot.links)
    assert worst_error(c, robot, model, data) < 1e-9
    assert bases["full"].rank == numerical_rank(model, data, "full", np.random.default_rng(2))
    snapped = build(load_urdf(path))[0]
    exact_model, exact_data = pinocchio_chain(DATA / "kinova.urdf", robot.links)
    assert snapped["full"].rank == numerical_rank(exact_model, exact_data, "full", np.random.default_rng(2))
    assert bases["full"].rank > snapped["full"].rank  # the rounding breaks exact cancellations


def test_snap_effect_is_the_gravity_change_pinocchio_sees(files):
    """The reported effect of the first snap (shoulder_lift 1.5708 -> pi/2) against Pinocchio's
    gravity torques of the file with only that angle rounded, minus those of the exact file."""
    from dyngen.description.snap_effect import STATES, gravity_torques

    robot = load_urdf(files / "rounded.urdf")
    text = (DATA / "ur5_robot.urdf").read_text()
    one = text.replace("1.57079632679", ROUNDED, 1).replace("1.57079632679", repr(np.pi / 2))
    (files / "one_rounded.urdf").write_text(one)
    rounded, rdata = pinocchio_chain(files / "one_rounded.urdf", robot.links)
    exact, edata = pinocchio_chain(files / "exact.urdf", robot.links)
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (STATES, robot.dof))
    change = max(np.max(np.abs(pin.computeGeneralizedGravity(rounded, rdata, configuration(rounded, x))
                               - pin.computeGeneralizedGravity(exact, edata, configuration(exact, x)))) for x in q)
    assert robot.snaps[0].joint == "shoulder_lift_joint"
    assert abs(robot.snap_effects[0] - change) < 1e-9 * max(1.0, change) + 1e-12
    assert np.allclose(gravity_torques(robot, q[:5]),
                       [pin.computeGeneralizedGravity(exact, edata, configuration(exact, x)) for x in q[:5]],
                       rtol=0, atol=1e-9)
