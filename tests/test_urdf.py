"""Arms read from their URDF (example-robot-data's, tests/data/urdf/README.md) against Pinocchio
reading the same file: counts = numerical rank of its joint-torque regressor, and rnea, gravity,
M with the URDF's own inertials equal Pinocchio's."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from cbuild import compile_folder

from dyngen.atomic import write_folder
from dyngen.description import load_description
from dyngen.description.urdf import load_urdf
from dyngen.generate import build

DATA = Path(__file__).resolve().parent / "data" / "urdf"
ARMS = {"panda": ("panda.urdf", "panda_link8"), "ur3": ("ur3_robot.urdf", None), "ur5": ("ur5_robot.urdf", None),
        "ur10": ("ur10_robot.urdf", None), "kinova": ("kinova.urdf", None)}
N_STATES = 20


def pinocchio_chain(path: Path, links):
    """Pinocchio's model of the file with every joint not moving one of `links` locked at 0."""
    model = pin.buildModelFromUrdf(str(path))
    keep = {model.frames[model.getFrameId(link)].parentJoint for link in links}
    lock = [j for j in range(1, model.njoints) if j not in keep]
    if lock:
        model = pin.buildReducedModel(model, lock, pin.neutral(model))
    assert model.nv == len(links)
    return model, model.createData()


def configuration(model, q):
    """Pinocchio's q for joint angles q: a continuous joint (JointModelRUB) holds (cos, sin)."""
    out = []
    for joint, angle in zip(model.joints[1:], q):
        out += [np.cos(angle), np.sin(angle)] if joint.nq == 2 else [angle]
    return np.array(out)


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, float(np.max(np.abs(b)))))


def numerical_rank(model, data, kind, rng, samples=30) -> int:
    n = model.nv
    rows = []
    for _ in range(samples):
        q = configuration(model, rng.uniform(-np.pi, np.pi, n))
        if kind == "gravity":
            rows.append(pin.computeJointTorqueRegressor(model, data, q, np.zeros(n), np.zeros(n)).copy())
        else:
            rows.append(pin.computeJointTorqueRegressor(model, data, q, rng.standard_normal(n),
                                                        rng.standard_normal(n)).copy())
    sv = np.linalg.svd(np.vstack(rows), compute_uv=False)
    return int(np.sum(sv > 1e-9 * sv[0]))


@pytest.fixture(scope="module", params=sorted(ARMS))
def arm(request, tmp_path_factory):
    file, tip = ARMS[request.param]
    robot = load_urdf(DATA / file, tip_link=tip)
    bases, emitted = build(robot)
    out = tmp_path_factory.mktemp(request.param)
    write_folder(out / robot.name, emitted.files)
    return robot, bases, compile_folder(out / robot.name, out / "build"), DATA / file


def test_counts_are_the_numerical_rank_of_pinocchios_regressor(arm):
    robot, bases, _, path = arm
    model, data = pinocchio_chain(path, robot.links)
    rng = np.random.default_rng(3)
    assert bases["gravity"].rank == numerical_rank(model, data, "gravity", rng)
    assert bases["full"].rank == numerical_rank(model, data, "full", rng)
    model.gravity.linear[:] = 0
    assert bases["inertia"].rank == numerical_rank(model, data, "full", rng)


def test_torques_equal_pinocchios_from_the_same_urdf(arm):
    robot, _, c, path = arm
    model, data = pinocchio_chain(path, robot.links)
    p = np.concatenate([v.as_tuple() for v in robot.nominal])
    s = c("standard_from_dynamic", p)
    rng = np.random.default_rng(4)
    n = robot.dof
    for _ in range(N_STATES):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)
        x = configuration(model, q)
        assert rel_err(c("rnea", q, qd, qdd, s), pin.rnea(model, data, x, qd, qdd)) < 1e-9
        assert rel_err(c("gravity", q, s), pin.computeGeneralizedGravity(model, data, x)) < 1e-9
        M = pin.crba(model, data, x).copy()
        assert rel_err(c("mass_matrix", q, s), np.triu(M) + np.triu(M, 1).T) < 1e-9
