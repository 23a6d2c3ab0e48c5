"""URDF -> new parameters -> a copy of the user's URDF: it keeps names, joints, limits and meshes,
and Pinocchio and MuJoCo reading it give the dynamics of the new parameters (dyngen's C)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from oracles.random_params import random_parameters
from test_urdf import configuration, pinocchio_chain, rel_err
from urdf_built import built_urdf

from dyngen.export.urdf_copy import urdf_copy


@pytest.fixture(scope="module", params=["ur5", "kinova"])
def arm(request, tmp_path_factory):
    out = tmp_path_factory.mktemp("roundtrip")
    robot, _, c, path = built_urdf(request.param, tmp_path_factory)
    p = random_parameters(robot.dof, seed=7)
    copy = out / "copy.urdf"
    copy.write_text(urdf_copy(robot, p))
    return robot, c, p, path, copy


def test_copy_keeps_what_the_user_wrote(arm):
    _, _, _, original, copy = arm
    before, after = original.read_text(), copy.read_text()
    assert re.findall(r'filename="([^"]+)"', before) == re.findall(r'filename="([^"]+)"', after)
    for tag in ("joint", "limit", "axis"):
        a, b = ET.fromstring(before).iter(tag), ET.fromstring(after).iter(tag)
        assert [e.attrib for e in a] == [e.attrib for e in b]
    assert before.split("<robot")[0].count("<!--") == after.split("<robot")[0].count("<!--")  # header kept


def states(n, count=20):
    rng = np.random.default_rng(9)
    for _ in range(count):
        yield rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)


def test_pinocchio_reads_the_new_parameters(arm):
    robot, c, p, _, copy = arm
    model, data = pinocchio_chain(copy, robot.links)
    s = c("standard_from_dynamic", p)
    for q, qd, qdd in states(robot.dof):
        assert rel_err(c("rnea", q, qd, qdd, s), pin.rnea(model, data, configuration(model, q), qd, qdd)) < 1e-9


def test_mujoco_reads_the_new_parameters(arm, tmp_path):
    robot, c, p, _, copy = arm
    root = ET.fromstring(copy.read_text())
    for link in root.iter("link"):  # the meshes are not in the tests: geometry does not enter dynamics
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    stripped = tmp_path / "stripped.urdf"
    stripped.write_text(ET.tostring(root, encoding="unicode"))
    model = mujoco.MjModel.from_xml_path(str(stripped))
    model.opt.gravity[:] = [0, 0, -9.81]
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT  # joint limits: rnea has none
    data = mujoco.MjData(model)
    address = [model.jnt_dofadr[model.joint(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)).id]
               for j in range(model.njnt)]
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    order = [names.index(name) for name in _chain_joint_names(copy, robot)]
    s = c("standard_from_dynamic", p)
    for q, qd, qdd in states(robot.dof):
        data.qpos[:], data.qvel[:], data.qacc[:] = 0, 0, 0
        for k, j in enumerate(order):
            data.qpos[model.jnt_qposadr[j]], data.qvel[address[j]], data.qacc[address[j]] = q[k], qd[k], qdd[k]
        mujoco.mj_inverse(model, data)
        tau = np.array([data.qfrc_inverse[address[j]] for j in order])
        assert rel_err(c("rnea", q, qd, qdd, s), tau) < 1e-8


def _chain_joint_names(path, robot):
    joints = {j.get("name"): j for j in ET.fromstring(path.read_text()).findall("joint")}
    by_child = {j.find("child").get("link"): name for name, j in joints.items()}
    return [by_child[link] for link in robot.links]


def test_fresh_export_of_an_arm_read_from_urdf(arm):
    """dyngen's own URDF export (joint frames as links) of an arm read from a URDF, in Pinocchio."""
    from dyngen.export import to_urdf

    robot, c, p, _, _ = arm
    model = pin.buildModelFromXML(to_urdf(robot, p))
    data = model.createData()
    s = c("standard_from_dynamic", p)
    for q, qd, qdd in states(robot.dof):
        assert rel_err(c("rnea", q, qd, qdd, s), pin.rnea(model, data, q, qd, qdd)) < 1e-9
