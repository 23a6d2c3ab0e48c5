"""The Panda and the UR5 read from their URDF (example-robot-data) against the same arms from
their DH tables (examples/panda.yaml, examples/ur5.yaml): same counts, and the same torques in
the base frame up to the frames' known offsets, at 300 random states.

The offsets are stated here, read off the two descriptions (not fitted):
- Panda: examples/panda.yaml says "Link frame i = DH frame i = URDF frame panda_link<i>": no
  base turn, every joint the same sign and zero.
- UR5: ur_description's base_link is UR's DH base turned by pi about z (the URDF's own
  `base_link-base_fixed_joint` to the controller's `base` frame has rpy 0 0 -pi), and its zero
  pose is UR's (the arm stretched out horizontally): every joint the same sign and zero.
The test checks these statements on the kinematics first (each link frame of the arm read from
the URDF is a constant transform of DH frame i at every random state), then the torques.

The DH side is the tests' own reading of the YAML (tests/oracles: Arm and a Pinocchio model
built from its DH table), not dyngen's. The YAMLs carry other inertials than the URDFs (the
UR5's are UR's masses with cylinder inertias; the Panda's stop at link 7 while the URDF's tip
body carries the hand), so the torques are compared with the URDF's inertials moved into the
DH frames through those constant transforms. dyngen's DH counts equal the same ranks
(tests/test_generated_c.py); the multiplications side by side: BENCHMARKS.md, "Arms from
their URDF".
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from oracles import pinocchio_arm
from oracles.arm import Arm
from test_urdf import configuration, rel_err
from urdf_built import built_urdf, pinocchio_chain

from dyngen.description.joint_model import forward_kinematics

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
RZ_PI = np.diag([-1.0, -1.0, 1.0])
# arm: (YAML, base turn B: the URDF's base frame in the DH base frame, joint signs, joint zeros);
# q_DH = sign * q_URDF + zero, tau_URDF = sign * tau_DH
PAIRS = {"panda": ("panda.yaml", np.eye(3), [1] * 7, [0.0] * 7),
         "ur5": ("ur5.yaml", RZ_PI, [1] * 6, [0.0] * 6)}
STATES = 300


@pytest.fixture(scope="module", params=sorted(PAIRS))
def pair(request, tmp_path_factory):
    yaml, turn, signs, zeros = PAIRS[request.param]
    robot, bases, c, path = built_urdf(request.param, tmp_path_factory)
    return Arm.from_yaml(EXAMPLES / yaml), robot, bases, c, path, turn, np.array(signs, float), np.array(zeros)


def random_states(n, seed, count=STATES):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, (count, n)), rng.uniform(-2, 2, (count, n)), rng.uniform(-3, 3, (count, n))


def dh_frames(arm, q):
    """DH frame i in the base frame for each row of q, from the oracle's Pinocchio model."""
    model, data = pinocchio_arm.build(arm)
    ids = [model.getFrameId(f"frame{i + 1}") for i in range(arm.n)]
    out = []
    for row in q:
        pin.framesForwardKinematics(model, data, row)
        out.append([data.oMf[k].homogeneous.copy() for k in ids])
    return np.array(out)  # (T, n, 4, 4)


def urdf_frames(robot, q):
    """dyngen's link frame i (where its parameters of the arm read from the URDF live)."""
    out = np.zeros((len(q), robot.dof, 4, 4))
    for i, pose in enumerate(forward_kinematics(robot.joint_models, q)):
        out[:, i, :3, :3], out[:, i, :3, 3], out[:, i, 3, 3] = pose.R, pose.origin, 1
    return out


def constant_transforms(arm, robot, turn, zeros):
    """dyngen's link frame i of the URDF arm in DH frame i, from the two descriptions at zero."""
    B = np.eye(4)
    B[:3, :3] = turn
    return [np.linalg.inv(T_dh) @ B @ T_u for T_dh, T_u in zip(dh_frames(arm, zeros[None])[0],
                                                              urdf_frames(robot, np.zeros((1, arm.n)))[0])]


def test_counts_equal_the_dh_arms_ranks(pair):
    arm, _, bases, *_ = pair
    for kind in ("gravity", "inertia", "full"):
        assert bases[kind].rank == pinocchio_arm.regressor_rank(arm, kind, n_samples=40, seed=3), kind


def test_the_stated_offsets_relate_the_kinematics(pair):
    """With the stated base turn, signs and zeros, every link frame of the URDF arm is DH frame
    i times one constant transform at every random state, and the gravity vectors agree."""
    arm, robot, _, _, _, turn, signs, zeros = pair
    assert np.allclose(turn @ np.array(robot.gravity, dtype=float), arm.gravity)
    q, _, _ = random_states(arm.n, 5)
    B = np.eye(4)
    B[:3, :3] = turn
    X = np.array(constant_transforms(arm, robot, turn, zeros))
    assert np.max(np.abs(dh_frames(arm, signs * q + zeros) @ X - B @ urdf_frames(robot, q))) < 1e-12


def test_the_dh_arm_with_the_urdfs_inertials_has_the_urdfs_torques(pair):
    """The URDF's inertials (as dyngen lumped them) moved into the DH frames: the DH arm's torques
    (the oracle's Pinocchio model of the YAML) equal those of dyngen's C from the URDF, and
    Pinocchio's reading of the URDF itself."""
    arm, robot, _, c, path, turn, signs, zeros = pair
    moved = []
    for v, X in zip(robot.nominal, constant_transforms(arm, robot, turn, zeros)):
        R, p = X[:3, :3], X[:3, 3]
        xx, xy, xz, yy, yz, zz = v.I
        I = R @ np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]) @ R.T
        moved.append([v.m, *(R @ np.asarray(v.c) + p), I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]])
    dh_model, dh_data = pinocchio_arm.build(arm, np.concatenate(moved))
    urdf_model, urdf_data = pinocchio_chain(path, robot.links)
    q, qd, qdd = random_states(arm.n, 6)
    s = np.tile(c("standard_from_dynamic", np.concatenate([v.as_tuple() for v in robot.nominal])), (len(q), 1))
    n = arm.n
    ours = {"rnea": c.batch("rnea", q, qd, qdd, s), "gravity": c.batch("gravity", q, s),
            "mass_matrix": c.batch("mass_matrix", q, s).reshape(-1, n, n)}
    qx, qdx, qddx = signs * q + zeros, signs * qd, signs * qdd
    dh = {"rnea": [signs * pin.rnea(dh_model, dh_data, *x) for x in zip(qx, qdx, qddx)],
          "gravity": [signs * pin.computeGeneralizedGravity(dh_model, dh_data, x) for x in qx],
          "mass_matrix": [np.outer(signs, signs) * symmetric(pin.crba(dh_model, dh_data, x)) for x in qx]}
    x = [configuration(urdf_model, row) for row in q]
    direct = {"rnea": [pin.rnea(urdf_model, urdf_data, *v).copy() for v in zip(x, qd, qdd)],
              "gravity": [pin.computeGeneralizedGravity(urdf_model, urdf_data, v).copy() for v in x],
              "mass_matrix": [symmetric(pin.crba(urdf_model, urdf_data, v)) for v in x]}
    for name in ours:
        assert rel_err(ours[name], np.array(dh[name])) < 1e-9, name
        assert rel_err(np.array(direct[name]), np.array(dh[name])) < 1e-9, name
    assert np.max(np.abs(ours["gravity"])) > 1.0  # the comparison is not of zeros


def symmetric(M):
    M = np.array(M)
    return np.triu(M) + np.triu(M, 1).T
