"""The consistent identification's recordings, a block of samples at a time (memory of one
block, not of the recording: the regressor of 3.6 M samples of 7 joints would be 8 GB).

A Source is one recording as the fit reads it, in passes: every pass (the normal equations,
each search of a column's setting, the statistics) reads its blocks again.
  - from its file (Source.of_file), when conditioning the recording would use its columns as
    recorded (qd and qdd recorded, no filter: what streaming/step.py reads in blocks): the
    blocks are read from the file on every pass;
  - from conditioned signals held whole (Source.held: positions to differentiate, a zero-phase
    filter and the automatic cutoff need the whole recording): the blocks are slices of them.
Both give the same blocks of the same samples (the data samples, the filter's start-up cut),
so one code path serves a recording of any length; a recording read whole is the in-memory
computation with blocks of any size (tests/test_consistent_identification.py).

The Coulomb column follows the velocity with a lag (columns.lagged): a block's column is
computed with the previous block's velocities before it, which is the whole recording's column
wherever the lag is shorter than a block (LAG_GRID: at most 40 ms).
"""

from __future__ import annotations

import itertools
import os
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from ..terms import tilt
from .columns import Piece, coulomb_matrix
from .identify_options import LAG_GRID

ROWS = 8192  # samples per block (7 joints x 50 regressor columns of them: 23 MB)
BEFORE = 1024  # rows of the block before that a worker reads (1 s at 1 kHz): enough for any lag of LAG_GRID
_IDENTIFICATIONS = itertools.count()


@dataclass
class Source:
    name: str
    rows: int  # data samples
    t0: float  # time of the first and last data sample (the contiguous parts)
    t1: float
    qd_max: np.ndarray  # (N,) largest |qd|: the velocity limits' default
    note: str  # what conditioning did
    warnings: list = field(default_factory=list)
    signals: object = None  # the conditioned recording, held whole (None: read from `path`)
    path: str | None = None
    dof: int = 0
    bag: object = None  # data.rosbag.BagReading: how a ROS 2 bag is read (None: its defaults)
    block_rows: int = ROWS
    sample: object = None  # the sanity check's windows, made from the parse's blocks (commands/recordings.py)
    _coulomb: dict = field(default_factory=dict)  # (smoothing, lags) -> whole column, this pass (held)
    _gravity: dict = field(default_factory=dict)  # the tilt's G(q) per block (held)
    _parsed: bool = False  # the file's blocks are in the temporary folder
    _temporary: object = None  # tempfile.TemporaryDirectory: removed with the Source
    _log: object = None  # data.log_quality.Streamed of the parse: the repeated rows left out
    _starts: list = field(default_factory=list)  # a parsed file's blocks: first data sample, samples
    _sizes: list = field(default_factory=list)

    @classmethod
    def held(cls, signals, block_rows: int = ROWS) -> "Source":
        keep = _kept(signals)
        t = signals.t[keep]
        return cls(signals.name, t.size, float(t[0]), float(t[-1]), np.abs(signals.qd[~signals.in_gaps()]).max(axis=0),
                   getattr(signals, "note", ""), list(getattr(signals, "warnings", [])), signals,
                   block_rows=block_rows)

    @classmethod
    def of_file(cls, path, dof: int, bag=None, block_rows: int = ROWS, tap=None) -> "Source":
        """The file parsed once, its blocks kept for every pass: its length, time span and
        velocities, and whether it moves and has torques (data.recording.check_informative).
        tap(block): each block as read, before the repeated rows are left out (the sanity check's sample)."""
        from ..forked import roomy_heap

        roomy_heap()  # the passes' block-sized arrays reused, not mapped afresh
        source = cls(Path(path).name, 0, 0.0, 0.0, np.zeros(dof), "qd, qdd as recorded, no filter", path=str(path),
                     dof=dof, bag=bag, block_rows=block_rows)
        first, source.moved, source.torque = None, False, False
        for block in source._file_blocks(tap):
            first = first or block
            source.rows += block.t.size
            source.qd_max = np.maximum(source.qd_max, np.abs(block.qd).max(axis=0))
            source.moved = source.moved or bool(np.ptp(np.r_[first.q[:1], block.q], axis=0).max() > 0)
            source.torque = source.torque or bool(np.any(block.tau))
        source.name, source.t0, source.t1 = first.name, float(first.t[0]), float(block.t[-1])
        log = source._log.report  # what data.conditioning would say of the rows as the logger wrote them
        source.note = "; ".join(log.notes + [source.note])
        source.warnings += log.warnings
        return source

    def blocks(self):
        """(signals of the block: t, q, qd, qdd, tau; the block before it or None; its number;
        index of its first sample among the data samples) per block. A file is parsed on the
        first pass only: its blocks are kept in a temporary folder for the next passes."""
        if self.signals is not None:
            s, keep = self.signals, _kept(self.signals)
            cut = {k: getattr(s, k)[keep] for k in ("t", "q", "qd", "qdd", "tau")}
            for number, a in enumerate(range(0, self.rows, self.block_rows)):
                part = slice(a, a + self.block_rows)
                yield SimpleNamespace(**{k: v[part] for k, v in cut.items()}), None, number, a
            return
        before, start = None, 0
        for number, block in enumerate(self._file_blocks()):
            yield block, before, number, start
            before, start = block, start + block.t.size

    def _file_blocks(self, tap=None):
        from ..data.chunks import chunks
        from ..data.log_quality import Streamed

        folder = self._folder()
        if self._parsed:
            yield from map(self.block, range(len(self._starts)))
            return
        self._log = Streamed()  # repeated rows left out as data.conditioning does
        # each block written by a thread while the next is read (the write is system time in the
        # kernel, without the GIL: the parse is one process, the other core free); one write at a time
        with ThreadPoolExecutor(1) as writer:
            written = None
            read = chunks(self.path, self.dof, True, (), self.block_rows, self.bag)
            for number, block in enumerate(self._log.blocks(read if tap is None else _tapped(read, tap))):
                data = np.column_stack([block.t, block.q, block.qd, block.qdd, block.tau])
                if written is not None:
                    written.result()
                written = writer.submit(np.save, os.path.join(folder, f"{number}.npy"), data)
                self._starts.append(sum(self._sizes))
                self._sizes.append(block.t.size)
                yield block
            if written is not None:
                written.result()
        self._parsed = True

    def block(self, number: int, last: int | None = None) -> SimpleNamespace:
        """Block `number` of a parsed file, from the temporary folder (last: its last rows only)."""
        data, n = np.load(os.path.join(self._folder(), f"{number}.npy"), mmap_mode="r" if last else None), self.dof
        data = np.array(data[-last:]) if last else data
        return SimpleNamespace(t=data[:, 0], q=data[:, 1:1 + n], qd=data[:, 1 + n:1 + 2 * n],
                               qdd=data[:, 1 + 2 * n:1 + 3 * n], tau=data[:, 1 + 3 * n:])

    def gravity(self, number: str, make) -> np.ndarray:
        """make(), kept in the temporary folder for the next passes (the tilt's G(q): forward
        kinematics in Python, the slowest part of a block)."""
        if self.signals is not None:  # held whole: G beside it in memory (3/4 of its signals' size)
            if number not in self._gravity:
                self._gravity[number] = make()
            return self._gravity[number]
        path = os.path.join(self._folder(), f"gravity{number}.npy")
        if os.path.exists(path):
            return np.load(path)
        out = make()
        np.save(path, out)
        return out

    def _folder(self) -> str:
        if self._temporary is None:
            self._temporary = tempfile.TemporaryDirectory(prefix="dyngen-blocks-")
        return self._temporary.name

    def coulomb(self, block, before, start, smoothing, lags) -> np.ndarray:
        """(T, N): the Coulomb column of the block, as columns.coulomb_matrix of the whole recording."""
        if self.signals is not None:  # through the recording's own filter: computed whole, once a pass
            key = (tuple(np.broadcast_to(smoothing, (self.qd_max.size,))), tuple(np.broadcast_to(lags, (self.qd_max.size,))))
            if key not in self._coulomb:
                self._coulomb[key] = coulomb_matrix(self.signals, smoothing, lags)[_kept(self.signals)]
            return self._coulomb[key][start:start + block.t.size]
        if before is None or not np.any(lags):  # no lag: the block's own rows (tanh row by row: the same numbers)
            return coulomb_matrix(block, smoothing, lags)
        joined = SimpleNamespace(t=np.r_[before.t, block.t], qd=np.vstack([before.qd, block.qd]))
        return coulomb_matrix(joined, smoothing, lags)[before.t.size:]


def _tapped(blocks, tap):
    for block in blocks:
        tap(block)
        yield block


def _kept(signals):
    """The data samples (Signals.inner: not the filter's start-up at the ends, nor the samples interpolated
    in a long gap of the stamps with the filter's reach around it): a slice where they are contiguous (views,
    as the arithmetic has always seen them), else a boolean mask. Where a gap is left out, the samples
    either side of it follow each other in a block: what is computed along the time (the Coulomb column's
    lag) is computed on the whole recording first; the residuals' correlation time and batch means
    (statistics.py) see one join in a series of thousands of samples."""
    keep = signals.inner()
    k = np.flatnonzero(keep)
    return slice(int(k[0]), int(k[-1]) + 1) if k.size and k[-1] - k[0] + 1 == k.size else keep


class Blocks:
    """Pieces (columns.Piece) of every block of every source, their label columns at the current
    settings (smoothing, lags: per joint; tilt(G) -> (T, N, 2) of gravity(q) -> G (T, N, 3)):
    iterated once per pass."""

    def __init__(self, model, sources, parts, labels, smoothing, lags, gravity=None, g_vec=None):
        self.model, self.sources, self.parts, self.labels = model, sources, parts, labels
        self.smoothing, self.lags, self.gravity, self.tilt = smoothing, lags, gravity, tilt_columns(g_vec)
        self.along = None if g_vec is None else tilt_along(g_vec)
        self.token = next(_IDENTIFICATIONS)  # the sources' kept G(q) are this identification's (its prior's)
        self.rigid = None  # base coefficients: the pieces carry Y rigid (statistics.estimate), not Y

    def __iter__(self):
        for source, part in zip(self.sources, self.parts):
            source._coulomb.clear()
            for block, before, number, start in source.blocks():
                yield self.piece(source, part, block, before, number, start)

    def each(self, work, workers: int = 2):
        """work(piece) for every piece, in order: for parsed files in two worker processes (both
        cores, forked.in_order), forked now so that they see this pass's settings,
        reading their blocks from the temporary folder; in block order, so what the caller sums
        is summed as in one process."""
        from ..forked import in_order

        if workers < 2 or not all(s._parsed for s in self.sources):
            yield from map(work, self)
            return
        tasks = [(i, n) for i, s in enumerate(self.sources) for n in range(len(s._starts))]
        yield from in_order(lambda task: work(_piece_of(self, task)), tasks, workers)

    def piece(self, source, part, block, before, number, start) -> Piece:
        if self.rigid is not None:  # a pass that needs Y rigid only: the inverse dynamics, no regressor
            Y, rigid = None, self.model.batch("inverse_dynamics", block.q, block.qd, block.qdd, self.rigid)
        else:
            Y, rigid = self.model.batch("regressor", block.q, block.qd, block.qdd), None
        if isinstance(part, int):
            at = np.full(block.t.size, part, dtype=int)
        else:  # contiguous stretches of equal duration: parts[0] of them
            u = (block.t - source.t0) / max(source.t1 - source.t0, 1e-300)
            at = np.minimum((u * part[0]).astype(int), part[0] - 1)
        # Yj joint by joint as a view, not a copy: BLAS takes the rows of one joint at their stride
        p = Piece(block, slice(None), None if Y is None else Y.transpose(1, 0, 2), np.asarray(block.tau, dtype=float),
                  at, {})
        p.source, p.start, p.rigid = source, start, rigid
        p.coulomb = lambda smoothing, lags: source.coulomb(block, before, start, smoothing, lags)
        coulomb = p.coulomb(self.smoothing, self.lags) if any(k == "coulomb" for k, _ in self.labels) else None
        tilted = None
        if any(k == "tilt" for k, _ in self.labels):
            p.gravity = source.gravity(f"{self.token}-{number}", lambda: self.gravity(block.q))
            tilted = self.tilt(p.gravity)
            p.along = p.gravity @ self.along  # the hidden column of the tilt's rotation (normal.py: rotated)
        p.columns = {lab: p.column(lab, coulomb, tilted) for lab in self.labels}
        return p


def _piece_of(blocks, task) -> Piece:
    """In a worker process: the piece of block `number` of source i, read from the temporary folder."""
    i, number = task
    source = blocks.sources[i]
    # the Coulomb column's lag (at most LAG_GRID's 40 ms) reaches into the block before: its last rows suffice
    before = source.block(number - 1, last=BEFORE) if number else None
    if before is not None and before.t[-1] - before.t[0] <= max(LAG_GRID):  # a fast recording: all of it
        before = source.block(number - 1)
    return blocks.piece(source, blocks.parts[i], source.block(number), before, number, source._starts[number])


def sources_of(recordings, block_rows: int = ROWS) -> list:
    """Sources of conditioned signals or of Sources (as they are)."""
    return [r if isinstance(r, Source) else Source.held(r, block_rows) for r in recordings]


def tilt_columns(g_vec, a=(0.0, 0.0)):
    """G (T, N, 3) -> the tilt's columns linearised at a (terms.tilt.Tilt.regressor)."""
    if g_vec is None:
        return None
    D, size = tilt.directions(g_vec), float(np.linalg.norm(g_vec))
    return lambda G: tilt.Tilt.regressor(G, D[0], D[1], size, a)


def tilt_along(g_vec) -> np.ndarray:
    """(3,): u1 x u2, G @ it the gravity torques along the axis; the tilt's columns at (a1, a2)
    are those at (0, 0) less a_d / (2 |g|) times them (terms/tilt.py Tilt.regressor)."""
    D = tilt.directions(g_vec)
    return np.cross(D[0], D[1])


def velocity_limits(robot, sources) -> np.ndarray:
    """V_j: the YAML's velocity limit, or else 1.5 times the largest |qd_j| in the data."""
    seen = np.max(np.vstack([s.qd_max for s in sources]), axis=0)
    out = []
    for j, joint in enumerate(robot.joints):
        lim = joint.limits.velocity if joint.limits is not None and joint.limits.velocity else None
        out.append(lim if lim is not None else 1.5 * max(seen[j], 1e-3))
    return np.array(out, dtype=float)
