"""URDF and MJCF export: Pinocchio (URDF) and MuJoCo (MJCF) inverse dynamics equal the
generated Newton-Euler C for every example arm, and the exported DH frames are the DH ones."""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT, build_arm
from oracles import lagrangian as lag
from oracles.arm import Arm, nominal_parameters
from oracles.random_params import random_parameters, random_rotation

from dyngen.description import load_robot
from dyngen.export import to_mjcf, to_urdf, write_all
from dyngen.export.frames import quaternion, rpy

N_STATES = 20
TOL = 1e-9


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, float(np.max(np.abs(b)))))


def random_state(robot, rng):
    n = robot.dof
    q = rng.uniform(-np.pi, np.pi, n)
    for i, joint in enumerate(robot.joints):
        if not joint.revolute:
            q[i] = rng.uniform(0.2, 1.0)
    return q, rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)


def load_pinocchio(urdf_path, robot):
    model = pin.buildModelFromUrdf(str(urdf_path))
    model.gravity.linear = np.array([float(g) for g in robot.gravity])
    return model, model.createData()


def load_mujoco(xml_path):
    model = mujoco.MjModel.from_xml_path(str(xml_path))
    # Test states go beyond the joint ranges (prismatic q in [0.2, 1]); the comparison is of
    # rigid-body dynamics, so limit constraints are switched off here, not in the file.
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    return model, mujoco.MjData(model)


def mujoco_inverse(model, data, q, qd, qdd):
    data.qpos[:], data.qvel[:], data.qacc[:] = q, qd, qdd
    mujoco.mj_inverse(model, data)
    return data.qfrc_inverse.copy()


def dh_poses(robot, q) -> list[np.ndarray]:
    """Base-frame poses of DH frames 1..N from the DH formulas of the Lagrangian oracle."""
    T, out = np.eye(4), []
    for joint, qi in zip(robot.joints, q):
        a, alpha, d, theta = (float(x) for x in (joint.a, joint.alpha, joint.d, joint.theta))
        T = T @ lag.dh_transform(robot.convention, a, alpha, d + (0.0 if joint.revolute else qi),
                                 theta + (qi if joint.revolute else 0.0))
        out.append(T)
    return out


@pytest.fixture(scope="module")
def exported(built, tmp_path_factory):
    p = random_parameters(built.robot.dof, seed=7)
    paths = write_all(built.robot, p, tmp_path_factory.mktemp(f"export_{built.name}"))
    return p, {path.suffix: path for path in paths}


# Arms the examples do not cover: modified DH with prismatic joints, theta offsets, rotations
# at the rpy singularity (pitch = +-pi/2), tilted gravity, missing limits. The generator
# needs angles with rational sines (multiples of pi/2); GENERIC adds arbitrary angles, checked
# against the numpy Lagrangian oracle instead of generated C.
SYNTHETIC = {
    "synthetic_modified": """
name: synthetic_modified
dh: modified
gravity: [1.2, -0.5, -9.7]
joints:
  - {type: revolute,  a: 0,     alpha: 0,       d: 0.3,  theta: "pi/2"}
  - {type: prismatic, a: 0.1,   alpha: "pi/2",  d: 0.05, theta: "pi/2"}
  - {type: revolute,  a: -0.2,  alpha: "-pi/2", d: 0.1,  theta: "pi", limits: {lower: -1, upper: 2}}
  - {type: prismatic, a: 0.05,  alpha: "pi",    d: 0,    theta: "-pi/2"}
  - {type: revolute,  a: 0,     alpha: "-pi/2", d: 0.2,  theta: "pi/2"}
""",
    "synthetic_standard": """
name: synthetic_standard
dh: standard
gravity: [0, 9.81, 0]
joints:
  - {type: prismatic, a: 0.1,   alpha: "pi/2",  d: 0.2,  theta: "pi/2"}
  - {type: revolute,  a: 0.3,   alpha: "pi",    d: -0.1, theta: "pi/2"}
  - {type: revolute,  a: 0,     alpha: "-pi/2", d: 0.15, theta: "-pi/2"}
  - {type: prismatic, a: -0.05, alpha: "pi/2",  d: 0.02, theta: "pi"}
""",
}

GENERIC = {
    "modified": """
name: generic_modified
dh: modified
gravity: [1.2, -0.5, -9.7]
joints:
  - {type: revolute,  a: 0,     alpha: 0.4,  d: 0.3,  theta: 0.3}
  - {type: prismatic, a: 0.1,   alpha: 1.2,  d: 0.05, theta: -0.8}
  - {type: revolute,  a: -0.2,  alpha: -0.7, d: 0.1,  theta: 2.5}
  - {type: prismatic, a: 0.05,  alpha: 3.0,  d: 0,    theta: 0.25}
""",
    "standard": """
name: generic_standard
dh: standard
gravity: [0.3, 0.2, -9.81]
joints:
  - {type: prismatic, a: 0.1,   alpha: 0.9,  d: 0.2,  theta: -1.3}
  - {type: revolute,  a: 0.3,   alpha: -2.2, d: -0.1, theta: 0.3}
  - {type: revolute,  a: 0,     alpha: 0.5,  d: 0.15, theta: 1.9}
  - {type: prismatic, a: -0.05, alpha: 1.1,  d: 0.02, theta: -0.6}
""",
}


@pytest.fixture(scope="module", params=sorted(SYNTHETIC))
def synthetic(request, tmp_path_factory):
    folder = tmp_path_factory.mktemp(request.param)
    path = folder / f"{request.param}.yaml"
    n = SYNTHETIC[request.param].count("type:")
    nominal = "".join("\n    - {m: 1, c: [0, 0, 0], I: [1, 0, 0, 1, 0, 1]}" for _ in range(n))
    path.write_text(SYNTHETIC[request.param] + "parameters:\n  nominal:" + nominal + "\n")  # build_arm wants them
    return build_arm(path, folder)


def test_rpy_and_quaternion_reproduce_the_rotation():
    rng = np.random.default_rng(2)
    rotations = [random_rotation(rng) for _ in range(50)]
    c, s = np.cos(0.4), np.sin(0.4)
    for sign in (1.0, -1.0):  # pitch = +-pi/2 (gimbal lock) with some yaw/roll mixed in
        rotations.append(np.array([[0, -s, sign * c], [0, c, sign * s], [-sign, 0, 0]], dtype=float))
    rotations += [np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
    for R in rotations:
        roll, pitch, yaw = rpy(R)
        assert np.allclose(pin.rpy.rpyToMatrix(roll, pitch, yaw), R, rtol=0, atol=1e-14)
        w, x, y, z = quaternion(R)
        assert np.allclose(pin.Quaternion(w, x, y, z).toRotationMatrix(), R, rtol=0, atol=1e-14)


def test_write_all_names_the_files(built, exported):
    _, paths = exported
    assert sorted(path.name for path in paths.values()) == [f"{built.name}.urdf", f"{built.name}.xml"]


def check_inverse_dynamics(built, p, paths):
    robot = built.robot
    s = built.c("standard_from_dynamic", p)
    pmodel, pdata = load_pinocchio(paths[".urdf"], robot)
    mmodel, mdata = load_mujoco(paths[".xml"])
    assert pmodel.nq == pmodel.nv == mmodel.nq == mmodel.nv == robot.dof
    rng = np.random.default_rng(5)
    worst = {"pinocchio": 0.0, "mujoco": 0.0}
    for _ in range(N_STATES):
        q, qd, qdd = random_state(robot, rng)
        tau = built.c("rnea", q, qd, qdd, s)
        worst["pinocchio"] = max(worst["pinocchio"], rel_err(pin.rnea(pmodel, pdata, q, qd, qdd), tau))
        worst["mujoco"] = max(worst["mujoco"], rel_err(mujoco_inverse(mmodel, mdata, q, qd, qdd), tau))
    assert max(worst.values()) < TOL, worst


def test_urdf_and_mjcf_inverse_dynamics_match_generated_c(built, exported):
    check_inverse_dynamics(built, *exported)


def test_synthetic_arms_match_generated_c_and_dh_frames(synthetic, tmp_path):
    p = random_parameters(synthetic.robot.dof, seed=8)
    exported = (p, {path.suffix: path for path in write_all(synthetic.robot, p, tmp_path)})
    check_inverse_dynamics(synthetic, *exported)
    check_dh_frames(synthetic.robot, exported[1])
    check_limits_and_gravity(synthetic.robot, exported[1])


@pytest.mark.parametrize("convention", sorted(GENERIC))
def test_generic_angles_match_lagrangian_and_dh_frames(convention, tmp_path):
    path = tmp_path / "arm.yaml"
    path.write_text(GENERIC[convention])
    robot, arm = load_robot(path), Arm.from_yaml(path)
    p = random_parameters(robot.dof, seed=6)
    paths = {path.suffix: path for path in write_all(robot, p, tmp_path)}
    pmodel, pdata = load_pinocchio(paths[".urdf"], robot)
    mmodel, mdata = load_mujoco(paths[".xml"])
    rng = np.random.default_rng(4)
    for _ in range(N_STATES):
        q, qd, qdd = random_state(robot, rng)
        tau = lag.inverse_dynamics(arm, q, qd, qdd, p)
        assert rel_err(pin.rnea(pmodel, pdata, q, qd, qdd), tau) < TOL
        assert rel_err(mujoco_inverse(mmodel, mdata, q, qd, qdd), tau) < TOL
    check_dh_frames(robot, paths)
    check_limits_and_gravity(robot, paths)


def test_exported_dh_frames_match_dh_kinematics(built, exported):
    check_dh_frames(built.robot, exported[1])


def check_dh_frames(robot, paths):
    """DH frames 1..N of both files (URDF links, MJCF sites) at random q equal the product
    of the DH transforms; the URDF base is frame 0."""
    pmodel, pdata = load_pinocchio(paths[".urdf"], robot)
    mmodel, mdata = load_mujoco(paths[".xml"])
    rng = np.random.default_rng(9)
    for _ in range(3):
        q, _, _ = random_state(robot, rng)
        expected = dh_poses(robot, q)
        pin.framesForwardKinematics(pmodel, pdata, q)
        mdata.qpos[:] = q
        mujoco.mj_kinematics(mmodel, mdata)
        assert np.allclose(pdata.oMf[pmodel.getFrameId("base")].homogeneous, np.eye(4), atol=1e-12)
        for i, T in enumerate(expected, start=1):
            Tp = pdata.oMf[pmodel.getFrameId(f"dh_frame_{i}")].homogeneous
            site = mujoco.mj_name2id(mmodel, mujoco.mjtObj.mjOBJ_SITE, f"dh_frame_{i}")
            Rm, pm = mdata.site_xmat[site].reshape(3, 3), mdata.site_xpos[site]
            assert np.allclose(Tp, T, rtol=0, atol=1e-12), (i, Tp, T)
            assert np.allclose(Rm, T[:3, :3], rtol=0, atol=1e-12) and np.allclose(pm, T[:3, 3], rtol=0, atol=1e-12)


def test_limits_and_gravity_are_exported(built, exported):
    check_limits_and_gravity(built.robot, exported[1])


def check_limits_and_gravity(robot, paths):
    pmodel, _ = load_pinocchio(paths[".urdf"], robot)
    mmodel, _ = load_mujoco(paths[".xml"])
    assert np.allclose(mmodel.opt.gravity, [float(g) for g in robot.gravity])
    for i, joint in enumerate(robot.joints):
        if joint.limits is not None and joint.limits.lower is not None:
            assert pmodel.lowerPositionLimit[i] == joint.limits.lower == mmodel.jnt_range[i, 0]
            assert pmodel.upperPositionLimit[i] == joint.limits.upper == mmodel.jnt_range[i, 1]


def test_inconsistent_parameters_are_refused_naming_the_link(tmp_path):
    robot = load_robot(ROOT / "examples" / "stanford.yaml")
    p = nominal_parameters(ROOT / "examples" / "stanford.yaml")  # link 5 inconsistent as published
    for export in (to_urdf, to_mjcf):
        with pytest.raises(ValueError, match=r"link 5: inertia about the CoM is not positive definite"):
            export(robot, p)
    with pytest.raises(ValueError, match="link 5"):
        write_all(robot, p, tmp_path)
    assert list(tmp_path.iterdir()) == []  # nothing written

    good = random_parameters(robot.dof, seed=3)
    cases = {"link 2: mass": (10, 0.0),              # zero mass
             "link 3: .*not positive definite": (24, -1.0),  # Ixx < 0
             "link 1: .*triangle inequality": (9, 10.0)}     # Izz > Ixx + Iyy
    for message, (k, value) in cases.items():
        bad = good.copy()
        bad[k] = value
        for export in (to_urdf, to_mjcf):
            with pytest.raises(ValueError, match=message):
                export(robot, bad)
    with pytest.raises(ValueError, match="60 dynamic parameters"):
        to_urdf(robot, good[:-1])


def test_export_checks_are_the_one_consistency_check():
    """The export's refusal (frames.check_consistent) and the URDF copy's test of a chain link
    (urdf_copy._physical) against the pseudo-inertia written here, J = [[tr(I)/2 E - I, 0], [0, m]]
    with I about the centre of mass: a body exactly when J is positive semidefinite. The copy
    keeps room (MuJoCo rounds), so it may refuse a body but never accepts a non-body; random
    bodies, about half breaking the triangle inequality."""
    from dyngen.export.frames import check_consistent
    from dyngen.export.urdf_copy import _physical

    rng = np.random.default_rng(11)
    verdicts, copied = [], []
    for _ in range(400):
        m = rng.uniform(0.1, 5.0)
        c = rng.uniform(-0.2, 0.2, 3)
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        inertia = Q @ np.diag(rng.uniform(0.001, 0.1, 3)) @ Q.T
        J = np.block([[0.5 * np.trace(inertia) * np.eye(3) - inertia, np.zeros((3, 1))],
                      [np.zeros((1, 3)), np.array([[m]])]])
        smallest = np.linalg.eigvalsh(J)[0]
        if abs(smallest) < 1e-9:
            continue  # on the boundary: rounding decides
        expected = smallest > 0
        link = np.array([m, *c, inertia[0, 0], inertia[0, 1], inertia[0, 2], inertia[1, 1], inertia[1, 2],
                         inertia[2, 2]])
        try:
            check_consistent(link[None, :])
            refused = False
        except ValueError as error:
            assert "link 1: inertia about the CoM violates the triangle inequality" in str(error)
            refused = True
        assert refused == (not expected)
        about_origin = inertia + m * (c @ c * np.eye(3) - np.outer(c, c))  # standard parameters
        accepted = _physical(m, m * c, about_origin)
        assert not (accepted and not expected)
        verdicts.append(expected)
        copied.append(accepted)
    assert 100 < sum(verdicts) < len(verdicts) - 100  # both kinds, many of each
    assert sum(copied) > 0.9 * sum(verdicts)  # the room refuses only bodies near the boundary


def test_symbolic_gravity_is_refused_for_mjcf(tmp_path):
    text = (ROOT / "examples" / "lwr.yaml").read_text()
    variant = text.replace("gravity: [0, 0, -9.81]", "gravity: [gx, gy, gz]")
    assert variant != text
    path = tmp_path / "lwr.yaml"
    path.write_text(variant)
    robot = load_robot(path)
    p = random_parameters(robot.dof, seed=4)
    with pytest.raises(ValueError, match=r"gravity .*contains symbols \(gx, gy, gz\)"):
        to_mjcf(robot, p)
    with pytest.raises(ValueError, match="contains symbols"):
        write_all(robot, p, tmp_path / "out")
    assert not (tmp_path / "out").exists()
    # URDF carries no gravity: it still exports, and says gravity is symbolic.
    assert "gravity is symbolic" in to_urdf(robot, p)
