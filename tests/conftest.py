"""Shared fixtures: every example arm generated, compiled and paired with its oracles."""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

from dyngen import blas

blas.use_one_thread()  # before numpy loads: the tests run the numerics as the dyngen command does

import numpy as np  # noqa: E402
import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import shared_run  # noqa: E402
from cbuild import Compiled, compile_folder  # noqa: E402
from oracles.arm import Arm, nominal_parameters  # noqa: E402

from dyngen.atomic import write_folder  # noqa: E402
from dyngen.description import load_robot  # noqa: E402
from dyngen.generate import build  # noqa: E402

EXAMPLES = sorted(p for p in (ROOT / "examples").glob("*.yaml") if "\njoints:" in p.read_text())  # robots only
ARM_NAMES = [p.stem for p in EXAMPLES]


@dataclass
class Built:
    name: str
    yaml: Path
    robot: object
    bases: dict
    emitted: object
    c: Compiled
    arm: Arm  # the oracles' own reading of the same file
    nominal: np.ndarray  # dynamic parameters, from the oracles' reading


def derive(yaml_path: Path):
    """load_robot + build, once per distinct YAML in a test run (shared_run); a YAML that names
    another file (a URDF) is derived afresh, since its key would not cover that file."""
    text = Path(yaml_path).read_bytes()

    def make():
        robot = load_robot(yaml_path)
        return (robot, *build(robot))

    if b"urdf:" in text:
        return make()
    return shared_run.once("derived", shared_run.digest(Path(yaml_path).name, text), make)


def build_arm(yaml_path: Path, out: Path, gravity_values: dict | None = None) -> Built:
    """gravity_values: numbers for symbolic gravity entries, for the oracles' Arm."""
    robot, bases, emitted = derive(yaml_path)
    folder = out / "generated" / robot.name
    write_folder(folder, emitted.files)
    compiled = compile_folder(folder, out / "build")
    return Built(robot.name, yaml_path, robot, bases, emitted, compiled, Arm.from_yaml(yaml_path, gravity_values),
                 nominal_parameters(yaml_path))


@pytest.fixture(scope="session", autouse=True)
def _shared_run(tmp_path_factory):
    """The folder every xdist worker of this run shares (the workers' basetemps sit in it)."""
    base = tmp_path_factory.getbasetemp()
    shared_run.use((base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "shared")


@pytest.fixture(scope="session", params=ARM_NAMES)
def built(request, tmp_path_factory) -> Built:
    path = ROOT / "examples" / f"{request.param}.yaml"
    return build_arm(path, tmp_path_factory.mktemp(request.param))


@pytest.fixture(scope="session")
def lwr(tmp_path_factory) -> Built:
    return build_arm(ROOT / "examples" / "lwr.yaml", tmp_path_factory.mktemp("lwr_only"))
