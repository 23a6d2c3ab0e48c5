"""Arms read from the test URDFs, generated and compiled once per test process: test_urdf,
test_urdf_vs_yaml and test_urdf_roundtrip share them (each costs a build and a compile)."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin
from cbuild import compile_folder

from dyngen.atomic import write_folder
from dyngen.description.urdf import load_urdf
from dyngen.generate import build

DATA = Path(__file__).resolve().parent / "data" / "urdf"
ARMS = {"panda": ("panda.urdf", "panda_link8"), "ur3": ("ur3_robot.urdf", None), "ur5": ("ur5_robot.urdf", None),
        "ur10": ("ur10_robot.urdf", None), "kinova": ("kinova.urdf", None)}
_BUILT: dict = {}


def built_urdf(name: str, tmp_path_factory):
    """(robot, bases, compiled C, URDF path) of one of ARMS."""
    if name not in _BUILT:
        file, tip = ARMS[name]
        robot = load_urdf(DATA / file, tip_link=tip)
        bases, emitted = build(robot)
        out = tmp_path_factory.mktemp(f"urdf_{name}")
        write_folder(out / robot.name, emitted.files)
        _BUILT[name] = (robot, bases, compile_folder(out / robot.name, out / "build"), DATA / file)
    return _BUILT[name]


def pinocchio_chain(path: Path, links, base=None):
    """Pinocchio's model of the file with every joint not moving one of `links` locked at 0."""
    model = pin.buildModelFromUrdf(str(path))
    keep = {model.frames[model.getFrameId(link, pin.FrameType.BODY)].parentJoint for link in links}
    lock = [j for j in range(1, model.njoints) if j not in keep]
    if lock:
        model = pin.buildReducedModel(model, lock, pin.neutral(model))
    assert model.nv == len(links)
    return model, model.createData()


def mujoco_inverse(urdf_path: Path, joint_names, q, qd, qdd, tmp_path: Path):
    """MuJoCo's inverse dynamics of a URDF, per state (rows of q, qd, qdd) for the named joints
    in that order (others at 0). Visuals and collisions are dropped first: the meshes are not
    in the tests and geometry does not enter the dynamics; joint limits are switched off."""
    import xml.etree.ElementTree as ET

    import mujoco
    import numpy as np

    root = ET.fromstring(urdf_path.read_text())
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    stripped = tmp_path / f"stripped_{urdf_path.name}"
    stripped.write_text(ET.tostring(root, encoding="unicode"))
    model = mujoco.MjModel.from_xml_path(str(stripped))
    model.opt.gravity[:] = [0, 0, -9.81]
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT  # joint limits: rnea has none
    model.dof_damping[:] = 0  # a URDF's <dynamics damping> (the Panda's): rnea has no joint friction either
    model.dof_frictionloss[:] = 0
    data = mujoco.MjData(model)
    order = [model.joint(name).id for name in joint_names]
    tau = np.zeros(np.shape(q))
    for row, (a, b, c) in enumerate(zip(q, qd, qdd)):
        data.qpos[:], data.qvel[:], data.qacc[:] = 0, 0, 0
        for k, j in enumerate(order):
            data.qpos[model.jnt_qposadr[j]], data.qvel[model.jnt_dofadr[j]], data.qacc[model.jnt_dofadr[j]] = \
                a[k], b[k], c[k]
        mujoco.mj_inverse(model, data)
        tau[row] = [data.qfrc_inverse[model.jnt_dofadr[j]] for j in order]
    return tau


def chain_joint_names(urdf_path: Path, robot):
    """The URDF joints that move the robot's chain links, in chain order."""
    import xml.etree.ElementTree as ET

    by_child = {j.find("child").get("link"): j.get("name") for j in ET.fromstring(urdf_path.read_text()).findall("joint")}
    return [by_child[link] for link in robot.links]
