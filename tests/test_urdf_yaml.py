"""A YAML that points to a URDF and adds what the URDF lacks."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from dyngen.description import load_description

DATA = Path(__file__).resolve().parent / "data" / "urdf"


def test_yaml_adds_gravity_limits_and_bounds_to_the_urdf(tmp_path):
    shutil.copy(DATA / "panda.urdf", tmp_path / "panda.urdf")
    bounds = "\n".join("    - {m: [0, 9], c: [[-1, 1], [-1, 1], [-1, 1]], I: [[0, 1], [-1, 1], [-1, 1], [0, 1], [-1, 1], "
                       "[0, 1]]}" for _ in range(7))
    (tmp_path / "arm.yaml").write_text(
        "urdf: panda.urdf\ntip_link: panda_link8\nname: franka\ngravity: [0, 0, -9.8]\n"
        "limits:\n" + "".join(f"  - {{acceleration: {10 + k}}}\n" for k in range(7))
        + "parameters:\n  total_mass: [10, 30]\n  bounds:\n" + bounds + "\n")
    robot = load_description(tmp_path / "arm.yaml")
    direct = load_description(DATA / "panda.urdf", tip_link="panda_link8")
    assert (robot.name, robot.dof, robot.source) == ("franka", 7, "arm.yaml")
    assert float(robot.gravity[2]) == -9.8
    assert [j.limits.acceleration for j in robot.joints] == [10 + k for k in range(7)]
    assert [j.limits.velocity for j in robot.joints] == [j.limits.velocity for j in direct.joints]  # the URDF's kept
    assert robot.total_mass == (10.0, 30.0) and robot.upper[0].m == 9
    assert np.allclose([v.as_tuple() for v in robot.nominal], [v.as_tuple() for v in direct.nominal])


def test_yaml_cannot_point_outside_its_folder(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "arm.yaml").write_text("urdf: ../panda.urdf\n")
    run = subprocess.run([sys.executable, "-m", "dyngen", "generate", str(tmp_path / "sub" / "arm.yaml"), "-o",
                          str(tmp_path / "out")], capture_output=True, text=True, timeout=120)
    assert run.returncode != 0 and not (tmp_path / "out").exists()
    assert run.stderr.strip() == ('dyngen: error: arm.yaml: urdf: expected the name of a URDF in the description\'s '
                                  'folder, got "../panda.urdf"')
