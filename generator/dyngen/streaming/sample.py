"""A long recording for the full diagnosis: a bounded sample of it, and its gap over every row.

The diagnosis (dyngen.diagnosis) holds its rows and searches nonlinear settings on them: its
memory and time grow with the rows it is given. A recording longer than `max_rows` samples is
therefore read once, in blocks (data/chunks.py), and keeps only windows of `window` seconds
evenly spread over its length, at most `max_rows` samples in all. The spacing is found in the
same pass without knowing the length: windows start every `window` seconds, and whenever the
kept rows exceed the bound every other window goes and the spacing doubles, so the windows
kept are evenly spread (every 2^k-th) and hold between half the bound and the bound (when
two windows fit in it; else one is kept). Each
window is its own recording (conditioned on its own; the diagnosis cuts it into its 2-s
blocks), named `<file>@<start>s`. A recording within the bound is returned whole: the
diagnosis is then the in-memory one.

In the same pass every row goes into the survey's sums (gap.py: the nominal gap's RMS and mean
and the simple model's 4 x 4 factors per joint), so that the report gives the gap and the
simple model over the whole recording beside the diagnosis of the sample.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .gap import VELOCITY, Gap, GapTask, Sums
from .gap import run as gap_run
from .step import _local, _model

MAX_ROWS = 24000  # samples the diagnosis holds at most: 2 min at 200 Hz, 24 s at 1 kHz (about 0.6 GB)
WINDOW = 6.0  # s: three of the diagnosis' 2-s blocks, one of them selecting


@dataclass
class Sampled:
    recordings: list  # data.Recording: the recording whole, or its windows
    rows: int  # samples in the whole recording
    seconds: float  # its length
    gap: Gap | None  # the gap over every row (None: the recording is within the bound)

    @property
    def sampled(self) -> bool:
        return self.gap is not None


def spread(blocks, max_rows: int = MAX_ROWS, window: float = WINDOW, each=None):
    """(windows kept: lists of pieces, in time order; rows; first and last time) of the blocks
    (data.Recording), each block passed to each(block) on the way."""
    kept: dict[int, list] = {}  # window number -> its pieces
    stride, count, rows, t0, t_end = 1, 0, 0, None, None
    for piece in blocks:  # one block at a time, and the windows kept
        t0 = float(piece.t[0]) if t0 is None else t0
        rows += piece.t.size
        t_end = float(piece.t[-1])
        if each is not None:
            each(piece)
        number = np.floor((piece.t - t0) / window).astype(int)
        for w in np.unique(number[number % stride == 0]):
            part = _part(piece, number == w)
            kept.setdefault(int(w), []).append(part)
            count += part.t.size
        while count > max_rows and len(kept) > 1:  # every other window goes
            stride *= 2
            for w in [w for w in kept if w % stride]:
                count -= sum(p.t.size for p in kept.pop(w))
    return [kept[w] for w in sorted(kept)], rows, t0, t_end


def windows(path, dof: int, effort_topic=None, max_rows: int = MAX_ROWS, window: float = WINDOW) -> list:
    """The recording whole (within max_rows samples), else its evenly spread windows, read in blocks."""
    from ..data.chunks import chunks

    kept, rows, t0, _ = spread(chunks(path, dof, True, (), 8192, effort_topic), max_rows, window)
    if rows <= max_rows:
        return [_joined(kept[0][0].name, [p for w in kept for p in w])]
    return [_joined(f"{w[0].name}@{w[0].t[0] - t0:.0f}s", w) for w in kept]


def sample(task: GapTask, max_rows: int = MAX_ROWS, window: float = WINDOW) -> Sampled:
    from ..data.chunks import chunks

    blocks = chunks(task.path, task.dof, True, (), task.rows, task.effort_topic)
    first = next(blocks)
    local = _local(first, task.conditioning)
    model = _model(task.folder)
    sums = Sums.start(model, task.p, task.dof) if local else None

    def add(piece):
        if sums is not None:
            sums.add(piece.q, piece.qd, piece.qdd, piece.tau, np.tanh(piece.qd / VELOCITY))

    kept, rows, t0, t_end = spread(itertools.chain([first], blocks), max_rows, window, add)
    if rows <= max_rows:
        return Sampled([_joined(first.name, [p for w in kept for p in w])], rows, t_end - t0, None)
    gap = sums.result(first.name, True) if sums is not None else gap_run(task)  # the latter: read whole
    return Sampled([_joined(f"{first.name}@{w[0].t[0] - t0:.0f}s", w) for w in kept], rows, t_end - t0, gap)


def _part(r, mask):
    from ..data.recording import Recording

    cut = (lambda x: None if x is None else x[mask])
    return Recording(r.name, r.t[mask], r.q[mask], cut(r.tau), cut(r.qd), cut(r.qdd),
                     {k: v[mask] for k, v in r.extra.items()})


def _joined(name: str, pieces: list):
    from ..data.recording import Recording

    cat = (lambda xs: None if xs[0] is None else np.concatenate(xs))
    first = pieces[0]
    return Recording(name, cat([p.t for p in pieces]), cat([p.q for p in pieces]), cat([p.tau for p in pieces]),
                     cat([p.qd for p in pieces]), cat([p.qdd for p in pieces]),
                     {k: cat([p.extra[k] for p in pieces]) for k in first.extra})
