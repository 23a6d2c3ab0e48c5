"""Read one CSV recording and check it: header `t, q1..qN, tau1..tauN`, optional `qd*`, `qdd*` and
other columns (e.g. `M11, M12, ...`); every problem is an InputError naming file, line and column."""

from __future__ import annotations

import csv
import dataclasses
import io
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, printable, shorten
from ..untrusted import MAX_CSV_BYTES, read_text
from .as_written import ragged_note, time_base, without_copies, without_ragged_ends  # rows as loggers write them

# No robot's time [s], position [rad, m], velocity, acceleration or torque [Nm] comes near this;
# larger values (1e308) would overflow the least squares instead of naming the cell.
MAX_VALUE = 1e9
# No joint sensor samples faster than 1 MHz; a step of 1e-12 s (or 1e-300) is a unit error, and
# velocities from it would overflow. A column name is a short label; a row a few kB.
MIN_STEP = 1e-6
MAX_TIME = 1e19  # the time column may be a clock's absolute reading: nanoseconds since 1970 until 2286
MAX_NAME = 64
MAX_COLUMNS = 4000  # the stacked inertia matrix of 40 joints has 820
MAX_CELL = 64  # characters of one number
MAX_COMMENTS = 100  # lines starting with '#' above the header

_NUMBERED = re.compile(r"^(q|qd|qdd|tau)(\d+)$", re.ASCII)  # ASCII digits only: "q\u0661" is not q1


@dataclass
class Recording:
    """The columns of one file, as floats; qd and qdd are None when the file has none."""

    name: str  # the file name, for messages
    t: np.ndarray  # (T,)
    q: np.ndarray  # (T, N)
    tau: np.ndarray | None  # (T, N); None when the file was read without torques
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None
    extra: dict = field(default_factory=dict)  # other columns by name, (T,)
    copies: int = 0  # rows left out at reading: exact copies of the row before, stamp included
    read_note: str | None = None  # what reading did beyond parsing: rows missing values at the ends, the time's unit


def read_csv(path, dof: int, require_torques: bool = True, required: tuple = ()) -> Recording:
    """Read and check the CSV `path` for `dof` joints; `required`: further columns that must be present."""
    path = Path(path)
    name = printable(path.name)  # the name reaches comments of written files and the terminal
    text = read_text(path, MAX_CSV_BYTES)  # UTF-8 (plain or .gz), bounded; else one line naming the file
    if "\r" in text:  # Windows (CR LF) and old Mac (CR alone) line ends are line ends
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    head = text.split("\n", MAX_COMMENTS + 1)
    header_line, used = header_of(head)
    header = _header(name, header_line, used)
    columns = check_header(name, header, dof, require_torques, required, f"line {used} (header)")
    body = "\n".join(head[used:])
    body = without_trailing_commas(body) if header_line.rstrip().endswith(",") else body
    return from_columns(name, header, columns, _numbers(body, name, header, used + 1), dof,
                        lambda row: f"line {row + used + 1}")


def without_trailing_commas(text: str) -> str:
    """Rows of a writer that ends every line with a comma, as its header (a loop writing `value,`)."""
    return "\n".join(line[:-1] if line.endswith(",") else line for line in text.rstrip(" \n").split("\n")) + "\n"


def header_of(lines: list) -> tuple[str, int]:
    """(the header line, lines up to the data) of a file's first lines. Lines starting with '#' above
    the header are comments; where data follow them at once, the last is the header with its '#'
    (numpy.savetxt writes `# t,q1,...`)."""
    k = 0
    while k < min(len(lines) - 1, MAX_COMMENTS) and lines[k].lstrip().startswith("#"):
        k += 1
    if k and _numeric(lines[k]):
        return lines[k - 1].lstrip()[1:], k
    return lines[k], k + 1


def _numeric(line: str) -> bool:
    first = line.split(",", 1)[0].strip()
    try:
        float(first)
    except ValueError:
        return False
    return True


def csv_line(row: int) -> str:
    """Where data row `row` (0-based) is in a CSV file: the header is line 1."""
    return f"line {row + 2}"


def from_columns(name, header, columns, data, dof, where=csv_line) -> Recording:
    """The Recording of a checked header and its (T, len(header)) values; `where(row)` names a row."""
    data, head, tail = without_ragged_ends(data)
    data, copies, base, _ = checked_rows(name, header, columns["t"], data, lambda row: where(head + row))
    if data.shape[0] < 2:
        _check_time(name, data[:, columns["t"]], where)  # its message: too few samples
    said = "; ".join(x for x in (ragged_note(head, tail), base[2]) if x) or None
    return dataclasses.replace(as_recording(name, columns, data, dof), copies=copies, read_note=said)


def checked_rows(name, header, at_t: int, data: np.ndarray, where, last=None, base=None):
    """(data, copies, base, last) for the rows of a whole file or of one block of it: every value in
    range, the rows that copy the row before left out (without_copies), time increasing as written,
    then t in seconds from its origin (base: time_base of the file's first block, else of these rows),
    by at least MIN_STEP. `last`: the row before data's first, as written (reading in blocks); the
    same for the next block. `where(row)` names row `row` of data."""
    _check_values(name, header, data, where, at_t)
    data, copies, kept = without_copies(data, last)
    if not data.shape[0]:
        return data, copies, base, last
    raw = data[:, at_t].copy()
    joined = raw if last is None else np.r_[last[at_t], raw]
    at = (lambda row: where(int(kept[row - (last is not None)])))
    base = base or time_base(raw)
    origin, scale, _ = base
    if joined.size >= 2:
        _check_time(name, joined, at, increase_only=True)
        _check_time(name, (joined - origin) * scale, at)
    last = data[-1].copy()
    data[:, at_t] = (raw - origin) * scale
    return data, copies, base, last


def as_recording(name, columns, data, dof) -> Recording:
    """The Recording of checked values (a whole file, or a chunk of one: data/chunks.py)."""
    t = data[:, columns["t"]]

    def block(prefix):
        return data[:, [columns[f"{prefix}{j}"] for j in range(1, dof + 1)]] if f"{prefix}1" in columns else None

    numbered = {f"{p}{j}" for p in ("q", "qd", "qdd", "tau") for j in range(1, dof + 1)}
    extra = {h: data[:, k] for h, k in columns.items() if h != "t" and h not in numbered}
    return Recording(name, t, block("q"), block("tau"), block("qd"), block("qdd"), extra)


def _header(name, line: str, number: int = 1) -> list[str]:
    where = f"line {number} (header)"
    if len(line) > MAX_COLUMNS * (MAX_NAME + 1):
        raise InputError(name, where, f"{len(line)} characters; a header is a list of short column names")
    try:
        header = [h.strip() for h in next(csv.reader([line]), [])]
    except csv.Error as err:
        raise InputError(name, where, f"not CSV ({shorten(str(err))})") from None
    if len(header) > 1 and not header[-1]:
        header.pop()  # a comma ending every line (without_trailing_commas)
    if len(header) > MAX_COLUMNS:
        raise InputError(name, where, f"{len(header)} columns (at most {MAX_COLUMNS})")
    for k, h in enumerate(header):
        if len(h) > MAX_NAME:
            raise InputError(name, where, f"column {k + 1}'s name has {len(h)} characters (at most {MAX_NAME})")
    return header


def check_header(name, header, dof, require_torques=True, required=(), where="columns") -> dict:
    """{column name: index} of a header, or an InputError naming what is wrong (at `where`)."""
    if not header or header == [""]:
        raise InputError(name, where, "empty file; expected a header such as t, q1..qN, tau1..tauN")
    columns = {}
    for k, h in enumerate(header):
        if not h and k == 0 and len(header) > 1:
            continue  # a row index without a name (pandas' to_csv writes one): not read
        if not h:
            raise InputError(name, where, f"column {k + 1} has no name")
        if h in columns:
            raise InputError(name, where, f"column {shorten(h)} appears twice")
        columns[h] = k
    if "t" not in columns:
        sep = next((d for d in (";", "\t", " ", "|") if len(header) == 1 and d in header[0].strip()), None)
        if sep is not None:
            raise InputError(name, where, f"one column named {shorten(header[0])!r}: the values are separated by "
                             f"{sep!r}, not commas (CSV here is comma-separated: t,q1,...,tau1,...)")
        named = ", ".join(h for h in header[:6] if h) + (", ..." if len(header) > 6 else "")
        raise InputError(name, where, f"no time column t (expected t, q1..qN, tau1..tauN; the file has {shorten(named)})")
    found = {}
    for h in columns:
        m = _NUMBERED.match(h)
        if m:
            found.setdefault(m.group(1), set()).add(int(m.group(2)))
    prefixes = ["q", "tau"] if require_torques else ["q"]
    for prefix in ("q", "qd", "qdd", "tau"):
        numbers = found.get(prefix, set())
        if not numbers and prefix not in prefixes:
            continue
        expected = set(range(1, dof + 1))
        if numbers - expected:
            raise InputError(name, where, f"the robot has {dof} joints but the file has {prefix}{max(numbers)}")
        if expected - numbers:
            missing = ", ".join(f"{prefix}{j}" for j in sorted(expected - numbers))
            if numbers:
                raise InputError(name, where, f"the robot has {dof} joints but the file has only "
                                 f"{prefix}{min(numbers)}..{prefix}{max(numbers)} (missing {missing})")
            raise InputError(name, where, f"missing column(s) {missing}")
    if "qdd" in found and "qd" not in found:
        raise InputError(name, where, "qdd columns without qd columns")
    missing = [c for c in required if c not in columns]
    if missing:
        raise InputError(name, where, f"missing column(s) {', '.join(missing)}")
    return columns


def _numbers(body: str, name, header, first_line: int = 2) -> np.ndarray:
    """Fast path with numpy; on failure, a slow pass that finds the exact line and column."""
    try:
        with warnings.catch_warnings():  # an empty body is reported below, with its line
            warnings.simplefilter("ignore")
            data = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2, dtype=float)
    except ValueError:
        data = None
    if data is not None and data.ndim == 2 and data.shape[1] == len(header) and data.shape[0] > 0:
        return data
    rows = []
    line = first_line - 1
    try:
        for line, row in enumerate(csv.reader(io.StringIO(body)), start=first_line):
            if not row or all(not cell.strip() for cell in row):
                continue
            if len(row) != len(header):
                raise InputError(name, f"line {line}", f"{len(row)} values, the header has {len(header)} columns")
            rows.append([_cell(cell, name, line, column) for cell, column in zip(row, header)])
    except csv.Error as err:
        raise InputError(name, f"line {line + 1}", f"not CSV ({shorten(str(err))})") from None
    if not rows:
        raise InputError(name, f"line {first_line}", "no data rows after the header")
    return np.array(rows, dtype=float)


def _cell(cell: str, name, line, column) -> float:
    where = f"line {line}, column {shorten(column)}"
    if len(cell) > MAX_CELL:
        raise InputError(name, where, f"not a number ({len(cell)} characters)")
    if not cell.strip():
        return float("nan")  # a missing value: left out at the file's ends, named between complete rows
    try:
        return float(cell)
    except ValueError:
        raise InputError(name, where, f'not a number ("{shorten(cell.strip())}")') from None


def _check_values(name, header, data, where=csv_line, time=None) -> None:
    """Every value finite and at most MAX_VALUE in size; the column `time` (its index) at most MAX_TIME."""
    bound = np.full(data.shape[1], MAX_VALUE)
    if time is not None:
        bound[time] = MAX_TIME
    if (np.abs(data) <= bound).all():  # NaN fails the comparison, so this passes only good data;
        return  # the searches for the first bad cell (two argwhere, 1.4 s a 1 kHz hour) only when one is there
    for bad, what in ((~np.isfinite(data), "{} (NaN or infinite value; missing values are left out only at the file's "
                                           "start and end)"),
                      (np.abs(data) > bound, "{:g}: value out of range (|x| at most {:g})")):
        if bad.any():
            row, col = np.argwhere(bad)[0]
            raise InputError(name, f"{where(row)}, column {shorten(header[col])}",
                             what.format(float(data[row, col]), bound[col]))


def _check_time(name, t, where=csv_line, increase_only: bool = False) -> None:
    """t increases (as in the file), and once in seconds (increase_only False), by at least MIN_STEP."""
    if t.size < 2:
        raise InputError(name, "column t", f"{t.size} sample(s); at least 2 are needed")
    steps = np.diff(t)
    checks = ((steps <= 0, lambda k: f"time does not increase ({float(t[k + 1])!r} after {float(t[k])!r})" + (
                  "; rows with other values share the stamp: was the time written with too few digits?"
                  if steps[k] == 0 else "")),
              (steps < MIN_STEP, lambda k: f"a time step of {float(steps[k]):.3g} s (at least {MIN_STEP:g} s: "
                                           "no sensor samples faster than 1 MHz)"))
    for bad, what in checks[:1] if increase_only else checks:
        if bad.any():
            k = np.flatnonzero(bad)[0]
            raise InputError(name, f"{where(k + 1)}, column t", what(k))


def check_informative(recordings, need_motion: bool = True) -> None:
    """Refuse recordings that hold nothing to fit: every torque zero, or every joint still everywhere."""
    names = ", ".join(r.name for r in recordings)
    if recordings and all(r.tau is not None and not np.any(r.tau) for r in recordings):
        raise InputError(names, "columns tau*", "every torque is zero: nothing to fit (a recording of a robot "
                         "switched off?)")
    if need_motion and recordings and all(np.ptp(r.q, axis=0).max() == 0 for r in recordings):
        raise InputError(names, "columns q*", "no joint moves (every position is constant): a model of motion "
                         "cannot be fitted; record an exciting trajectory (dyngen excite)")
