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
