"""Recordings in columnar formats besides CSV: Parquet (pyarrow) and ROS 2 bags (rosbags).

A Parquet file holds the CSV's columns under the CSV's names (t, q1..qN, tau1..tauN, optional
qd*, qdd* and others); a ROS 2 bag holds sensor_msgs/JointState messages (positions,
velocities, efforts) and, optionally, the commanded effort on another topic. Both give the
Recording that data/recording.py gives for a CSV, through the same header and value checks,
and fail with one line naming the file and the row (message) or column. The files are
anyone's: regular files only, bounded in size, bounded in what they unpack to; their contents
are only ever read as numbers. pyarrow and rosbags are the optional extra `formats`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError, shorten
from ..untrusted import MAX_CSV_BYTES, regular_file
from .recording import Recording, check_header, from_columns

PARQUET = (".parquet", ".pq")
BAG_FILES = (".db3", ".mcap")  # the storage files of a ROS 2 bag, in its folder beside metadata.yaml
MAX_VALUES = MAX_CSV_BYTES // 8  # float64 values a file may unpack to (as many bytes as the largest CSV)
MAX_COLUMNS = 10000


def format_of(path) -> str | None:
    """"parquet", "rosbag" or None (CSV, the default)."""
    path = Path(path)
    if path.suffix.lower() in PARQUET:
        return "parquet"
    if path.suffix.lower() in BAG_FILES or (path.is_dir() and (path / "metadata.yaml").is_file()):
        return "rosbag"
    return None


def _module(name: str, path):
    try:
        return __import__(name, fromlist=["_"])
    except ImportError:
        raise InputError(Path(path).name, "", f"reading this format needs {name.split('.')[0]} "
                         "(pip install 'dyngen[formats]')") from None


def parquet_row(row: int) -> str:
    return f"row {row + 1}"


def read_parquet(path, dof: int, require_torques: bool = True, required: tuple = ()) -> Recording:
    name = Path(path).name
    header, batches = parquet_batches(path)
    columns = check_header(name, header, dof, require_torques, required)
    data = np.vstack([block for _, block in batches])
    return from_columns(name, header, columns, data, dof, where=parquet_row)


def parquet_batches(path, rows: int = 65536):
    """(header, iterator of (first row, (k, columns) float values)): the file checked for size,
    what it unpacks to, numeric columns, missing values."""
    name = Path(path).name
    regular_file(path, MAX_CSV_BYTES)
    pq = _module("pyarrow.parquet", path)
    pa = _module("pyarrow", path)
    try:
        f = pq.ParquetFile(path, pre_buffer=False)  # else a whole file may be buffered ahead: memory grows with it
        count, schema = f.metadata.num_rows, f.schema_arrow
    except Exception as err:  # noqa: BLE001 -- a broken file may raise anything from the library: one line
        raise InputError(name, "", f"not a readable Parquet file ({shorten(err, 200)})") from None
    header = [str(n) for n in schema.names]
    if len(header) > MAX_COLUMNS:
        raise InputError(name, "", f"{len(header)} columns (at most {MAX_COLUMNS})")
    if count * max(len(header), 1) > MAX_VALUES:
        raise InputError(name, "", f"{count} rows of {len(header)} columns: too large (at most {MAX_VALUES} values)")
    for field in schema:
        if not (pa.types.is_floating(field.type) or pa.types.is_integer(field.type)):
            raise InputError(name, f"column {shorten(field.name)}", f"type {field.type}: not numbers")
    if count == 0:
        raise InputError(name, parquet_row(0), "no data rows")

    def batches():
        start = 0
        try:
            # in this thread: arrow's decoding threads cost more system time than they save on blocks
            # this small (the 10-minute 1 kHz file: 0.14-0.42 against 0.04 s), and the cores are the workers'
            for batch in f.iter_batches(batch_size=rows, use_threads=False):
                # filled a column at a time into rows of a (columns, T) array, then transposed in one
                # copy: writing each column into a strided slice of (T, columns) took twice as long
                # (0.30 against 0.14 s per 10 minutes at 1 kHz); the values and layout are the same
                data = np.empty((len(header), batch.num_rows))
                for k, column in enumerate(batch.columns):
                    if column.null_count:
                        first = int(np.flatnonzero(column.is_null().to_numpy(zero_copy_only=False))[0])
                        raise InputError(name, f"{parquet_row(start + first)}, column {shorten(header[k])}",
                                         "missing value (null)")
                    data[k] = column.to_numpy(zero_copy_only=False)
                yield start, np.ascontiguousarray(data.T)
                start += batch.num_rows
        except InputError:
            raise
        except Exception as err:  # noqa: BLE001 -- as above
            raise InputError(name, parquet_row(start), f"not a readable Parquet file ({shorten(err, 200)})") from None
        if start != count:
            raise InputError(name, "", f"{start} rows read, the file's metadata says {count}")

    return header, batches()
