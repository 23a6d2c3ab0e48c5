"""Arms read from their URDF (example-robot-data's, tests/data/urdf/README.md) against Pinocchio
reading the same file: counts = numerical rank of its joint-torque regressor, and rnea, gravity,
M with the URDF's own inertials equal Pinocchio's."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
from urdf_built import ARMS, DATA, built_urdf, pinocchio_chain  # noqa: F401 (names other tests import)

STATES = 1000


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
    return built_urdf(request.param, tmp_path_factory)


def test_counts_are_the_numerical_rank_of_pinocchios_regressor(arm):
    robot, bases, _, path = arm
    model, data = pinocchio_chain(path, robot.links)
    rng = np.random.default_rng(3)
    assert bases["gravity"].rank == numerical_rank(model, data, "gravity", rng)
    assert bases["full"].rank == numerical_rank(model, data, "full", rng)
    model.gravity.linear[:] = 0
    assert bases["inertia"].rank == numerical_rank(model, data, "full", rng)


def snapped_copy(path, snaps, out):
    """The URDF with each snapped constant written as its exact value in double precision (the
    arm dyngen's snapped C describes), for Pinocchio; the tests' own rewrite of the XML."""
    import sympy

    root = ET.fromstring(path.read_text())
    joints = {j.get("name"): j for j in root.findall("joint")}  # not <transmission>s
    for snap in snaps:
        joint = joints[snap.joint]
        if snap.field == "axis":
            joint.find("axis").set("xyz", " ".join(snap.after.split()))
        else:
            k = int(snap.field[len("origin.rpy["):-1])
            rpy = joint.find("origin").get("rpy").split()
            rpy[k] = repr(float(sympy.sympify(snap.after)))
            joint.find("origin").set("rpy", " ".join(rpy))
    out.write_text(ET.tostring(root, encoding="unicode"))
    return out


def torques(c, robot, model, data, seed=4, count=STATES):
    """(dyngen, Pinocchio) for rnea, gravity and M at `count` random states; dyngen's C batched."""
    rng = np.random.default_rng(seed)
    n = robot.dof
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (count, n)), rng.uniform(-2, 2, (count, n)), rng.uniform(-3, 3, (count, n))
    s = np.tile(c("standard_from_dynamic", np.concatenate([v.as_tuple() for v in robot.nominal])), (count, 1))
    x = [configuration(model, row) for row in q]
    ours = {"rnea": c.batch("rnea", q, qd, qdd, s), "gravity": c.batch("gravity", q, s),
            "mass_matrix": c.batch("mass_matrix", q, s).reshape(count, n, n)}
    theirs = {"rnea": np.array([pin.rnea(model, data, *v).copy() for v in zip(x, qd, qdd)]),
              "gravity": np.array([pin.computeGeneralizedGravity(model, data, v).copy() for v in x]),
              "mass_matrix": np.array([np.triu(M) + np.triu(M, 1).T for M in
                                       (pin.crba(model, data, v).copy() for v in x)])}
    return ours, theirs


def test_torques_equal_pinocchios_on_the_snapped_urdf(arm, tmp_path):
    """1e-9 relative at 1000 states against Pinocchio reading the file with the snapped values."""
    robot, _, c, path = arm
    model, data = pinocchio_chain(snapped_copy(path, robot.snaps, tmp_path / path.name), robot.links)
    ours, theirs = torques(c, robot, model, data)
    for name in ours:
        assert rel_err(ours[name], theirs[name]) < 1e-9, name


def test_torques_on_the_original_urdf_are_within_the_snaps_effect(arm):
    """Against Pinocchio reading the ORIGINAL file (constants as written), 1000 states: gravity
    differs by at most the sum of the snaps' reported effects (each the largest gravity change
    that one snap makes), and rnea and M by as little (bench/results/urdf_accuracy.md)."""
    robot, _, c, path = arm
    model, data = pinocchio_chain(path, robot.links)
    ours, theirs = torques(c, robot, model, data)
    bound = 2 * sum(robot.snap_effects) + 1e-9 * max(1.0, float(np.max(np.abs(theirs["gravity"]))))
    assert np.max(np.abs(ours["gravity"] - theirs["gravity"])) <= bound
    for name in ours:
        assert rel_err(ours[name], theirs[name]) < (1e-9 if not robot.snaps else 1e-8), name
