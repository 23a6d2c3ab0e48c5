"""A recording read a block of rows at a time, for work whose memory must not grow with the
recording's length (identification by accumulated least squares: streaming/).

    for piece in chunks(path, dof):      # Recording objects of at most `rows` samples each
        ...

Every block goes through the checks read_recording applies to the whole file (header, numbers,
finite and bounded values, increasing time, also across blocks) and fails with the same one
line naming the file, line (row) and column, so the two readers accept and refuse the same
files. CSV (plain or .gz) and Parquet are read in blocks; a ROS 2 bag is read whole.
"""

from __future__ import annotations

import dataclasses
import gzip
import io
import warnings
import zlib
from itertools import islice
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..untrusted import MAX_CSV_BYTES, MAX_RATIO, RATIO_FROM, regular_file
from . import columnar
from .reader import read_recording
from .as_written import ragged_note, without_ragged_ends
from .recording import (MAX_COMMENTS, _check_time, _header, _numbers, as_recording, check_header, checked_rows,
                        csv_line, header_of, without_trailing_commas)

ROWS = 8192  # samples per block: 7 joints x 50 regressor columns of them is 23 MB


def chunks(path, dof: int, require_torques: bool = True, required: tuple = (), rows: int = ROWS,
           bag=None):
    """Recordings of consecutive blocks of at most `rows` samples (at least one block)."""
    kind = columnar.format_of(path)
    if kind == "rosbag":
        yield read_recording(path, dof, require_torques, required, bag)
        return
    blocks = _parquet_blocks(path, rows) if kind == "parquet" else _csv_blocks(path, rows)
    name = Path(path).name
    header, where_header = next(blocks)
    columns = check_header(name, header, dof, require_torques, required, where_header)
    last, total, base, head = None, 0, None, None
    for start, data, where in blocks:
        if head is None:  # rows missing a value at the file's start are left out (at its end they are refused:
            data, head, _ = without_ragged_ends(data, end=False)  # a block cannot know that no complete row follows)
            start += head
        data, copies, base, last = checked_rows(name, header, columns["t"], data, lambda row: where(start + row),
                                                last, base)  # base: the first block's origin and unit, for the file
        if not data.shape[0]:
            continue
        total += data.shape[0]
        said = "; ".join(x for x in (ragged_note(head, 0), base[2]) if x) or None
        yield dataclasses.replace(as_recording(name, columns, data, dof), copies=copies, read_note=said)
    if total < 2:
        _check_time(name, np.zeros(total), csv_line)  # the whole-file reader's message


def _csv_blocks(path, rows: int):
    """(The header, where it is), then (first row, (k, columns) values, where) per block of CSV lines."""
    path = Path(path)
    name = path.name
    regular_file(path, MAX_CSV_BYTES)
    raw = open(path, "rb")
    try:
        packed = path.suffix == ".gz"
        binary = gzip.GzipFile(fileobj=raw) if packed else raw
        # the whole-file reader's bounds (untrusted._gunzip): the size, and for .gz the unpacking ratio
        ratio = max(RATIO_FROM, MAX_RATIO * path.stat().st_size) if packed else None
        lines_of = io.BufferedReader(_Bounded(binary, name, MAX_CSV_BYTES, ratio, path.stat().st_size))
        try:
            head = lines_of.readline()
            if b"\r" in head.removesuffix(b"\r\n"):  # old Mac line ends (CR alone): as the whole-file reader
                lines_of = io.BytesIO((head + lines_of.read()).replace(b"\r\n", b"\n").replace(b"\r", b"\n"))
                head = lines_of.readline()
            ahead = [head]  # comment lines above the header (recording.header_of), and the line after them
            while len(ahead) <= MAX_COMMENTS and ahead[-1].lstrip().startswith(b"#"):
                ahead.append(lines_of.readline())
            text = _decoded(ahead, name, 1, 0, "utf-8-sig").split("\n")
            header_line, used = header_of([line.rstrip("\r") for line in text[:len(ahead)]])
            offset = sum(len(x) for x in ahead[:used])
            header = _header(name, header_line, used)  # the whole-file reader's bounds and message
            trailing = header_line.rstrip().endswith(",")
            yield header, f"line {used} (header)"
            first, start, pending = used + 1, 0, ahead[used:]
            while True:
                chunk = pending + list(islice(lines_of, rows - len(pending)))
                pending = []
                if not chunk:
                    break
                text = _decoded(chunk, name, first, offset)
                lines = (without_trailing_commas(text) if trailing else text).splitlines(keepends=True)
                offset += sum(len(x) for x in chunk)
                if any(x.strip() for x in lines):
                    data = _block(lines, name, header, first)
                    yield start, data, lambda row: f"line {row + used + 1}"
                    start += data.shape[0]
                first += len(chunk)
            if start == 0:
                raise InputError(name, f"line {used + 1}", "no data rows after the header")
        except (OSError, EOFError, zlib.error) as err:
            raise InputError(name, "", f"not a readable gzip file ({err or 'truncated'})") from None
    finally:
        raw.close()


def _decoded(chunk: list, name, first_line: int, offset: int, encoding: str = "utf-8") -> str:
    """The lines (starting at line first_line, byte offset of the file) as text, or the whole-file
    reader's InputError naming the line and byte that are not UTF-8."""
    data = b"".join(chunk)
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as err:
        line = first_line + data[:err.start].count(b"\n")
        raise InputError(name, f"line {line}", f"not UTF-8 text (byte {offset + err.start}); save the file as UTF-8"
                         ) from None


def _block(lines, name, header, first_line) -> np.ndarray:
    """The block's numbers (fast path numpy; else the slow pass naming line and column)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            data = np.loadtxt(lines, delimiter=",", ndmin=2, dtype=float)
        if data.ndim == 2 and data.shape[1] == len(header) and data.shape[0] > 0:
            return data
    except ValueError:
        pass
    return _numbers("".join(lines), name, header, first_line)


class _Bounded(io.RawIOBase):
    """A binary stream that refuses to deliver more than `limit` bytes (a small .gz may
    unpack to gigabytes)."""

    def __init__(self, inner, name, limit, ratio=None, packed_size=0):
        """ratio: for a .gz, the most it may unpack to (the whole-file reader's decompression-bomb rule)."""
        self.inner, self.name, self.left = inner, name, limit
        self.ratio, self.packed_size, self.delivered = ratio, packed_size, 0

    def readable(self):
        return True

    def readinto(self, buffer):
        data = self.inner.read(min(len(buffer), self.left + 1))
        if len(data) > self.left:
            raise InputError(self.name, "", f"file too large (at most {MAX_CSV_BYTES >> 20} MB)")
        self.left -= len(data)
        self.delivered += len(data)
        if self.ratio is not None and self.delivered > self.ratio:
            raise InputError(self.name, "", f"unpacks to more than {MAX_RATIO} times its size ({self.packed_size >> 10} "
                             f"kB to over {self.delivered >> 20} MB): a decompression bomb?")
        buffer[:len(data)] = data
        return len(data)


def _parquet_blocks(path, rows: int):
    header, batches = columnar.parquet_batches(path, rows)
    yield header, "columns"
    for start, data in batches:
        yield start, data, columnar.parquet_row
