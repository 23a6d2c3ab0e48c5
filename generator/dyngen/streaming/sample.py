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
from ..forked import roomy_heap
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


class Spread:
    """Evenly spread windows of blocks (data.Recording) given one at a time, at most max_rows
    samples in all (the module's rule); windows(name): the recording whole while within the
    bound, else its windows named <name>@<start>s."""

    def __init__(self, max_rows: int = MAX_ROWS, window: float = WINDOW):
        self.max_rows, self.window = max_rows, window
        self.kept: dict[int, list] = {}  # window number -> its pieces
        self.stride, self.count, self.rows, self.t0, self.t_end = 1, 0, 0, None, None

    def add(self, piece) -> None:
        if piece.t.size == 0:
            return
        self.t0 = float(piece.t[0]) if self.t0 is None else self.t0
        self.rows += piece.t.size
        self.t_end = float(piece.t[-1])
        number = np.floor((piece.t - self.t0) / self.window).astype(int)
        for w in np.unique(number[number % self.stride == 0]):
            part = _part(piece, number == w)
            self.kept.setdefault(int(w), []).append(part)
            self.count += part.t.size
        while self.count > self.max_rows and len(self.kept) > 1:  # every other window goes
            self.stride *= 2
            for w in [w for w in self.kept if w % self.stride]:
                self.count -= sum(p.t.size for p in self.kept.pop(w))

    def windows(self, name: str) -> list:
        kept = [self.kept[w] for w in sorted(self.kept)]
        if self.rows <= self.max_rows:
            return [_joined(name, [p for w in kept for p in w])]
        return [_joined(f"{name}@{w[0].t[0] - self.t0:.0f}s", w) for w in kept]


@dataclass(frozen=True)
class Rows:
    """Every row of a recording, for a pass over it in blocks (diagnosis/pipeline.py block_segments)."""
    path: str
    dof: int
    bag: object = None  # data.rosbag.BagReading: how a ROS 2 bag is read (None: its defaults)
    rows: int = 8192
    span: tuple | None = None  # (from, to) s: only the rows from <= t < to (a --split piece; to = inf: to the end)


def windows(path, dof: int, bag=None, max_rows: int = MAX_ROWS, window: float = WINDOW,
            conditioning=None) -> list:
    """The recording whole (within max_rows samples), else its evenly spread windows, read in
    blocks; windows whose blocks are conditioned on their own (step._local under `conditioning`)
    are marked with their recording's Rows (w.stream), so that the test figures can read every row."""
    from ..data.chunks import chunks

    spread, name, first = Spread(max_rows, window), None, None
    for block in chunks(path, dof, True, (), 8192, bag):
        spread.add(block)
        name, first = block.name, first or block
    got = spread.windows(name)
    if len(got) > 1 and conditioning is not None and _local(first, conditioning):
        for w in got:
            w.stream = Rows(str(path), dof, bag)
    return got


def sample(task: GapTask, max_rows: int = MAX_ROWS, window: float = WINDOW) -> Sampled:
    from ..data.chunks import chunks
    from ..data.log_quality import Streamed

    roomy_heap()
    blocks = chunks(task.path, task.dof, True, (), task.rows, task.bag)
    first = next(blocks)
    local = _local(first, task.conditioning)
    model = _model(task.folder)
    sums = Sums.start(model, task.p, task.dof) if local else None
    spread = Spread(max_rows, window)
    rows = Streamed().blocks(itertools.chain([first], blocks)) if local else itertools.chain([first], blocks)
    for piece in rows:  # one block at a time (repeated rows left out as conditioning does), and the windows kept
        spread.add(piece)
        if sums is not None:
            sums.add(piece.q, piece.qd, piece.qdd, piece.tau, np.tanh(piece.qd / VELOCITY))
    seconds = spread.t_end - spread.t0
    if spread.rows <= max_rows:
        return Sampled(spread.windows(first.name), spread.rows, seconds, None)
    gap = sums.result(first.name, True) if sums is not None else gap_run(task)  # the latter: read whole
    windows = spread.windows(first.name)
    for w in windows if local else ():
        w.stream = task  # the diagnosis' final fit reads every row of it (diagnosis/pipeline.py every_row)
    return Sampled(windows, spread.rows, seconds, gap)


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
