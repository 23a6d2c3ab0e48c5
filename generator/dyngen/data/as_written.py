"""Rows as loggers write them, before they are a Recording (data/recording.py): rows with a missing
value at a file's ends, rows that copy the row before stamp and all, and a time column in another unit
or on an absolute clock. Each says what it did, for the notes."""

from __future__ import annotations

import numpy as np

ABSOLUTE = 1e6  # a first stamp beyond this (11 days in seconds) is an absolute clock: t counted from it
# A joint-torque log is written at 20 Hz to 20 kHz: a median step of 0.05 ms to 50 ms in seconds. Stamps in
# ms, us or ns are found by the step that lands there; each range below leaves a gap to the one before
# (a step of 0.05-0.2 "s" or 50-200 "ms" is read as it stands, not guessed).
UNITS = (("s", 1.0, 5e-5, 0.05), ("ms", 1e-3, 0.2, 50.0), ("us", 1e-6, 200.0, 5e4), ("ns", 1e-9, 2e5, 5e7))


def without_ragged_ends(data: np.ndarray, end: bool = True) -> tuple[np.ndarray, int, int]:
    """(data without the rows at its start (and its end) that miss a value (NaN or an empty cell: a
    logger writing before every column has one, or after one stopped), how many at the start, at the
    end). A missing value between complete rows is left for the checks to name."""
    complete = ~np.isnan(data).any(axis=1)
    if not complete.any():
        return data, 0, 0
    first = int(np.argmax(complete))
    last = data.shape[0] - int(np.argmax(complete[::-1])) if end else data.shape[0]
    return data[first:last], first, data.shape[0] - last


def ragged_note(head: int, tail: int) -> str | None:
    if not head and not tail:
        return None
    return (f"{head} row(s) at the start and {tail} at the end miss a value (a logger writing before every column "
            "had one, or after one stopped): left out")


def time_base(t: np.ndarray) -> tuple[float, float, str | None]:
    """(origin, scale, note): seconds from the start are (t - origin) * scale. An absolute clock's
    stamps (Unix time) are counted from the first; stamps in ms, us or ns are found by their median
    step (UNITS), and said in the note."""
    origin = float(t[0]) if t.size and abs(float(t[0])) > ABSOLUTE else 0.0
    step = float(np.median(np.diff(t))) if t.size >= 2 else 0.0
    unit, scale = next(((u, k) for u, k, low, high in UNITS if low <= step <= high), ("s", 1.0))
    said = []
    if origin:
        said.append(f"t starts at {origin:.6g} {unit} (an absolute clock): counted from the first row")
    if unit != "s":
        said.append(f"t read in {unit}: its median step {step:.3g} would be a {1 / step:.3g} Hz log in seconds, "
                    f"{1 / (step * scale):.4g} Hz in {unit}")
    return origin, scale, "; ".join(said) or None


def without_copies(data: np.ndarray, before=None) -> tuple[np.ndarray, int, np.ndarray]:
    """(data without the rows that copy the row before in every column, stamp included (a logger or an
    export writing one message twice: they carry nothing), how many, the kept rows' indices in data).
    `before`: the row before data's first (reading in blocks)."""
    same = same_as_before(data, before)
    kept = np.flatnonzero(~same)
    return data[kept], int(same.sum()), kept


def same_as_before(data: np.ndarray, before=None) -> np.ndarray:
    """Boolean (T,): rows equal in every column to the row before (`before`: the one before the first)."""
    same = np.zeros(data.shape[0], dtype=bool)
    same[1:] = np.all(data[1:] == data[:-1], axis=1)
    if before is not None and data.shape[0]:
        same[0] = bool(np.all(data[0] == before))
    return same
