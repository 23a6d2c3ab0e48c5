"""End to end from a URDF: a YAML that points to the URDF and carries identified coefficients
(those of the URDF's own inertials perturbed by a few per cent: a consistent, known answer)
-> `dyngen extract` (the real command) -> the copy of the user's URDF with the extracted
parameters, which Pinocchio and MuJoCo read with the dynamics of the known parameters (rnea
against dyngen's C at 100 random states).

One arm by default (the UR5: each arm costs a generation and an extraction, about a minute on
the shared machine); DYNGEN_TEST_ALL_URDFS=1 runs all five of tests/data/urdf.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest
import yaml
from test_urdf import configuration, rel_err
from urdf_built import ARMS, DATA, built_urdf, chain_joint_names, mujoco_inverse, pinocchio_chain

NAMES = sorted(ARMS) if os.environ.get("DYNGEN_TEST_ALL_URDFS") else ["ur5"]
STATES = 100


def perturbed(robot, seed=1) -> np.ndarray:
    """The URDF's parameters with masses and inertias about the centre of mass scaled by up to
    +-5 % and the centres of mass moved by up to 5 mm: still physically consistent."""
    rng = np.random.default_rng(seed)
    P = np.array([v.as_tuple() for v in robot.nominal])
    P[:, 0] *= 1 + 0.05 * rng.uniform(-1, 1, len(P))
    P[:, 1:4] += 0.005 * rng.uniform(-1, 1, (len(P), 3))
    P[:, 4:] *= (1 + 0.05 * rng.uniform(-1, 1, len(P)))[:, None]
    return P.ravel()


def identified_yaml(folder, name, robot, c, p):
    file, tip = ARMS[name]
    shutil.copy(DATA / file, folder / file)
    P = p.reshape(-1, 10)
    doc = {"urdf": file, **({"tip_link": tip} if tip else {}), "identified": {},
           "parameters": {"bounds": [{"m": [0, float(2 * m)], "c": [[-0.6, 0.6] for _ in range(3)],
                                      "I": [list(b) for b in ((0, 1), (-1, 1), (-1, 1), (0, 1), (-1, 1), (0, 1))]}
                                     for m in P[:, 0]]}}
    for kind in ("gravity", "inertia"):
        expressions = c.manifest["coefficients"][kind]["expressions"]
        doc["identified"][kind] = [{"coefficient": e["standard"], "value": float(v)}
                                   for e, v in zip(expressions, c(f"pi_{kind}", p))]
    path = folder / "arm.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


@pytest.fixture(scope="module", params=NAMES)
def extracted(request, tmp_path_factory):
    robot, _, c, original = built_urdf(request.param, tmp_path_factory)
    folder = tmp_path_factory.mktemp(f"extract_{request.param}")
    p = perturbed(robot)
    path = identified_yaml(folder, request.param, robot, c, p)
    run = subprocess.run([sys.executable, "-m", "dyngen", "extract", str(path), "-o", str(folder / "generated"),
                          "--out", str(folder / "out"), "--restarts", "4", "--global", "none", "-q"],
                         capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stderr
    stem = ARMS[request.param][0][:-len(".urdf")]
    copy = folder / "out" / robot.name / f"{stem}_with_parameters.urdf"
    assert copy.exists(), sorted(p.name for p in (folder / "out" / robot.name).iterdir())
    rng = np.random.default_rng(9)
    n = robot.dof
    states = rng.uniform(-np.pi, np.pi, (STATES, n)), rng.uniform(-2, 2, (STATES, n)), rng.uniform(-3, 3, (STATES, n))
    s = np.tile(c("standard_from_dynamic", p), (STATES, 1))
    return robot, copy, states, c.batch("rnea", *states, s), original


def test_pinocchio_reads_the_extracted_copy_with_the_known_dynamics(extracted):
    robot, copy, (q, qd, qdd), tau, _ = extracted
    model, data = pinocchio_chain(copy, robot.links)
    theirs = np.array([pin.rnea(model, data, configuration(model, a), b, c).copy() for a, b, c in zip(q, qd, qdd)])
    assert rel_err(tau, theirs) < 1e-8


def test_mujoco_reads_the_extracted_copy_with_the_known_dynamics(extracted, tmp_path):
    robot, copy, (q, qd, qdd), tau, _ = extracted
    theirs = mujoco_inverse(copy, chain_joint_names(copy, robot), q, qd, qdd, tmp_path)
    assert rel_err(tau, theirs) < 1e-8


def test_the_copy_differs_from_the_original_where_the_parameters_moved(extracted):
    """Not a copy of the file's inertials: the perturbation is visible in Pinocchio's masses."""
    robot, copy, _, _, path = extracted
    model, _ = pinocchio_chain(copy, robot.links)
    original, _ = pinocchio_chain(path, robot.links)
    masses = [model.inertias[j].mass for j in range(1, model.njoints)]
    before = [original.inertias[j].mass for j in range(1, original.njoints)]
    assert max(abs(a - b) / b for a, b in zip(masses, before)) > 1e-3
