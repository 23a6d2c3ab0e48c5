"""Simulator export: URDF (Pinocchio, ROS tools) and MuJoCo MJCF of a robot with given
dynamic parameters. Both use the DH q as joint positions."""

from __future__ import annotations

from pathlib import Path

from ..atomic import write_file
from .mjcf import to_mjcf
from .urdf import to_urdf

__all__ = ["to_mjcf", "to_urdf", "write_all"]


def write_all(robot, p, folder, joint_dynamics=None) -> list[Path]:
    """Write <name>.urdf and <name>.xml (MJCF) into folder; both are built before either is
    written, so an error (inconsistent p, symbolic gravity) leaves the folder untouched.
    joint_dynamics: optional per-joint friction and rotor inertia (see to_mjcf)."""
    texts = {f"{robot.name}.urdf": to_urdf(robot, p, joint_dynamics=joint_dynamics),
             f"{robot.name}.xml": to_mjcf(robot, p, joint_dynamics=joint_dynamics)}
    if robot.urdf_file is not None:  # read from a URDF: the parameters also go into a copy of it
        from .urdf_copy import urdf_copy

        texts[f"{Path(robot.urdf_file).stem}_with_parameters.urdf"] = urdf_copy(robot, p)
    paths = []
    for name, text in texts.items():
        path = Path(folder) / name
        write_file(path, text)
        paths.append(path)
    return paths
