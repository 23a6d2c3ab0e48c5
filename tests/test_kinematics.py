"""The kinematics functions (link poses, flange pose, Jacobians, Jdot qd) of every example arm
against Pinocchio and a numpy oracle (complex-step derivatives of FK, differences of J), at
random states, 1e-9 relative; plus an arm with a rotated, offset tool and a prismatic joint."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, build_arm
from oracles import kinematics as kin

N_STATES = 30
TOL = 1e-9


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, float(np.max(np.abs(b)))))


def random_state(built, rng):
    n = built.robot.dof
    q = rng.uniform(-np.pi, np.pi, n)
    for i, joint in enumerate(built.robot.joints):
        if not joint.revolute:
            q[i] = rng.uniform(0.2, 1.0)
    return q, rng.uniform(-2, 2, n)


def check_kinematics(built, states=N_STATES, seed=3):
    rng = np.random.default_rng(seed)
    n = built.robot.dof
    tool = kin.tool_matrix(built.yaml)
    model, data = kin.pinocchio_model(built.arm, tool)
    worst = {}
    for _ in range(states):
        q, qd = random_state(built, rng)
        numpy_poses = kin.poses(built.arm, tool, q)
        pin_side = kin.pinocchio_kinematics(model, data, n, q, qd)
        link_poses = built.c("link_poses", q).reshape(n, 4, 4)
        link_jacobians = built.c("link_jacobians", q).reshape(n, 6, n)
        J = built.c("jacobian", q)
        checks = {
            "link_poses / numpy": (link_poses, np.array(numpy_poses[:n])),
            "link_poses / pinocchio": (link_poses, np.array(pin_side["poses"][:n])),
            "flange_pose / numpy": (built.c("flange_pose", q), numpy_poses[-1]),
            "flange_pose / pinocchio": (built.c("flange_pose", q), pin_side["poses"][-1]),
            "jacobian / numpy": (J, kin.jacobian(built.arm, tool, q)),
            "jacobian / pinocchio": (J, pin_side["jacobians"][-1]),
            "jacobian_dot_qd / numpy": (built.c("jacobian_dot_qd", q, qd), kin.jacobian_dot_qd(built.arm, tool, q, qd)),
            "jacobian_dot_qd / pinocchio": (built.c("jacobian_dot_qd", q, qd), pin_side["jdot_qd"]),
        }
        for i in range(n):
            checks[f"link_jacobians[{i + 1}] / numpy"] = (link_jacobians[i], kin.jacobian(built.arm, tool, q, i + 1))
            checks[f"link_jacobians[{i + 1}] / pinocchio"] = (link_jacobians[i], pin_side["jacobians"][i])
        for name, (got, want) in checks.items():
            worst[name] = max(worst.get(name, 0.0), rel_err(got, want))
    bad = {k: v for k, v in worst.items() if not v < TOL}
    assert not bad, bad


def test_kinematics_match_pinocchio_and_numpy(built):
    check_kinematics(built)


TOOL = '\ntool: {xyz: [0.01, -0.02, 0.126], rpy: [0.3, "pi/2", -0.7]}\n'
# joint offsets on top: a revolute joint's theta, and the prismatic joint's d on the Stanford arm
OFFSETS = {"stanford": ("d: 0,     theta: \"-pi/2\"", "d: 0.1,   theta: \"-pi/2\""),
           "puma560": ("theta: 0", "theta: 0.3"), "panda": ("theta: 0", "theta: -1.1")}


@pytest.mark.parametrize("name", sorted(OFFSETS))
def test_a_rotated_offset_tool_and_joint_offsets(name, tmp_path):
    """A tool with all three angles (one exact) and an offset in every direction, and joint
    offsets (standard and modified DH; the Stanford arm's prismatic joint)."""
    text = (ROOT / "examples" / f"{name}.yaml").read_text()
    old, new = OFFSETS[name]
    assert old in text
    text = text.replace(old, new, 1)
    if "\ntool:" in text:  # panda has its flange already: replace it
        text = "\n".join(line for line in text.splitlines() if not line.startswith("tool:")) + "\n"
    yaml = tmp_path / f"{name}.yaml"
    yaml.write_text(text + TOOL)
    check_kinematics(build_arm(yaml, tmp_path), states=10, seed=5)


def test_no_tool_means_the_last_link_frame(lwr):
    q = np.linspace(-1, 1, lwr.robot.dof)
    assert np.array_equal(lwr.c("flange_pose", q), lwr.c("link_poses", q)[-4:])
    assert np.array_equal(lwr.c("jacobian", q), lwr.c("link_jacobians", q)[-6:])


def test_at_1000_states_against_pinocchio(built):
    """The issue's 1000 states: every C call batched (one C loop), Pinocchio (forwardKinematics,
    computeJointJacobians, the classical acceleration) in a python loop over one model."""
    rng = np.random.default_rng(11)
    n = built.robot.dof
    Q, QD = (np.array(x) for x in zip(*(random_state(built, rng) for _ in range(1000))))
    model, data = kin.pinocchio_model(built.arm, kin.tool_matrix(built.yaml))
    pin_side = [kin.pinocchio_kinematics(model, data, n, q, qd) for q, qd in zip(Q, QD)]
    batch = built.c.batch
    checks = {"link_poses": (batch("link_poses", Q).reshape(-1, n, 4, 4), [s["poses"][:n] for s in pin_side]),
              "flange_pose": (batch("flange_pose", Q), [s["poses"][-1] for s in pin_side]),
              "jacobian": (batch("jacobian", Q), [s["jacobians"][-1] for s in pin_side]),
              "link_jacobians": (batch("link_jacobians", Q).reshape(-1, n, 6, n), [s["jacobians"][:n] for s in pin_side]),
              "jacobian_dot_qd": (batch("jacobian_dot_qd", Q, QD), [s["jdot_qd"] for s in pin_side])}
    worst = {}
    for name, (got, want) in checks.items():
        got, want = np.asarray(got).reshape(len(Q), -1), np.asarray(want).reshape(len(Q), -1)
        worst[name] = float(np.max(np.max(np.abs(got - want), axis=1) / np.maximum(1.0, np.max(np.abs(want), axis=1))))
    assert all(err < TOL for err in worst.values()), worst
