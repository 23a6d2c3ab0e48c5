"""Other vendors' arms, from their URDFs as example-robot-data ships them (tests/data/urdf/README.md),
through the real command `dyngen generate`: counts = numerical rank of Pinocchio's joint-torque
regressor and rnea, gravity, M equal Pinocchio's (1e-9, 200 states) on the file with the
snapped values; on the original file gravity is within the sum of the reported snap effects.

- double_pendulum_continuous: `continuous` joints (Pinocchio: JointModelRUBY, q = (cos, sin)).
- finger_edu: a 3-joint finger with fixed-joint links lumped (Open Dynamic Robot Initiative).
- so101 (SO-ARM100): pi written 3.14159 and pi/2 1.5708 (9 snaps), a moving jaw beyond the
  chosen tip link, locked and lumped; two leaves, so the tip link is named.
- xarm7 (UFactory, 7 joints, 6 snaps): only with DYNGEN_TEST_ALL_URDFS=1 (a minute to generate).
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from cbuild import compile_folder
from test_urdf import numerical_rank, rel_err, snapped_copy, torques
from urdf_built import DATA, pinocchio_chain

from dyngen.description.urdf import load_urdf

ARMS = {"double_pendulum_continuous": None, "finger_edu": None, "so101": "gripper_link"}
if os.environ.get("DYNGEN_TEST_ALL_URDFS"):
    ARMS["xarm7"] = None


@pytest.fixture(scope="module", params=sorted(ARMS))
def generated(request, tmp_path_factory):
    path, tip = DATA / f"{request.param}.urdf", ARMS[request.param]
    out = tmp_path_factory.mktemp(request.param)
    run = subprocess.run([sys.executable, "-m", "dyngen", "generate", str(path), "-o", str(out / "generated"), "-q",
                          *(["--tip-link", tip] if tip else [])], capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stderr
    robot = load_urdf(path, tip_link=tip)
    c = compile_folder(out / "generated" / robot.name, out / "build")
    return robot, c, path, snapped_copy(path, robot.snaps, out / path.name)


def test_counts_are_pinocchios_rank_on_the_snapped_file(generated):
    robot, c, _, snapped = generated
    model, data = pinocchio_chain(snapped, robot.links)
    counts = {kind: len(c.manifest["coefficients"][kind]["expressions"]) for kind in ("gravity", "full")}
    assert counts["gravity"] == numerical_rank(model, data, "gravity", np.random.default_rng(1))
    assert counts["full"] == numerical_rank(model, data, "full", np.random.default_rng(2))


def test_torques_equal_pinocchios_on_the_snapped_file(generated):
    robot, c, _, snapped = generated
    model, data = pinocchio_chain(snapped, robot.links)
    ours, theirs = torques(c, robot, model, data, count=200)
    for name in ours:
        assert rel_err(ours[name], theirs[name]) < 1e-9, name


def test_gravity_on_the_original_file_within_the_snaps_effect(generated):
    robot, c, path, _ = generated
    model, data = pinocchio_chain(path, robot.links)
    ours, theirs = torques(c, robot, model, data, count=200)
    bound = 2 * sum(robot.snap_effects) + 1e-9 * max(1.0, float(np.max(np.abs(theirs["gravity"]))))
    assert np.max(np.abs(ours["gravity"] - theirs["gravity"])) <= bound
