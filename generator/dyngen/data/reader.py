"""A recording in any format dyngen reads: CSV (recording.py), Parquet files and ROS 2 bags
(columnar.py, rosbag.py), all into the same Recording through the same checks."""

from __future__ import annotations

from pathlib import Path

from .columnar import format_of, read_parquet
from .recording import Recording, read_csv
from .rosbag import read_bag


def read_recording(path, dof: int, require_torques: bool = True, required: tuple = (),
                   effort_topic: str | None = None) -> Recording:
    """Read and check `path` for `dof` joints (`required`: further columns; `effort_topic`: a bag's)."""
    kind = format_of(Path(path))
    if kind == "parquet":
        return read_parquet(path, dof, require_torques, required)
    if kind == "rosbag":
        return read_bag(path, dof, require_torques, effort_topic)
    return read_csv(path, dof, require_torques, required)
