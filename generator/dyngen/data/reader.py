"""A recording in any format dyngen reads: CSV (recording.py), Parquet files and ROS 2 bags
(columnar.py, rosbag.py), all into the same Recording through the same checks."""

from __future__ import annotations

from pathlib import Path

from .columnar import format_of, read_parquet
from .recording import Recording, read_csv
from .rosbag import read_bag


def read_recording(path, dof: int, require_torques: bool = True, required: tuple = (),
                   bag=None) -> Recording:
    """Read and check `path` for `dof` joints (`required`: further columns; `bag`: how a ROS 2 bag is
    read, a rosbag.BagReading)."""
    kind = format_of(Path(path))
    if kind == "parquet":
        return read_parquet(path, dof, require_torques, required)
    if kind == "rosbag":
        return read_bag(path, dof, require_torques, bag)
    return read_csv(path, dof, require_torques, required)
