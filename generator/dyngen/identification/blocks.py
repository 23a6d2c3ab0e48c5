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
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from .columns import Piece, coulomb_matrix

ROWS = 8192  # samples per block (7 joints x 50 regressor columns of them: 23 MB)


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
    effort_topic: str | None = None
    block_rows: int = ROWS
    _coulomb: dict = field(default_factory=dict)  # (smoothing, lags) -> whole column, this pass (held)

    @classmethod
    def held(cls, signals, block_rows: int = ROWS) -> "Source":
        keep = _kept(signals)
        t = signals.t[keep]
        return cls(signals.name, t.size, float(t[0]), float(t[-1]), np.abs(signals.qd).max(axis=0),
                   getattr(signals, "note", ""), list(getattr(signals, "warnings", [])), signals,
                   block_rows=block_rows)

    @classmethod
    def of_file(cls, path, dof: int, effort_topic=None, block_rows: int = ROWS) -> "Source":
        """One pass over the file: its length, time span and velocities (and the checks of
        data.recording.check_informative on its blocks)."""
        from ..data.chunks import chunks

        rows, t0, t1, qd_max, moved, torque = 0, None, None, np.zeros(dof), False, False
        first = None
        for block in chunks(path, dof, True, (), block_rows, effort_topic):
            first = first or block
            rows += block.t.size
            t0 = float(block.t[0]) if t0 is None else t0
            t1 = float(block.t[-1])
            qd_max = np.maximum(qd_max, np.abs(block.qd).max(axis=0))
            moved = moved or bool(np.ptp(np.r_[first.q[:1], block.q], axis=0).max() > 0)
            torque = torque or bool(np.any(block.tau))
        source = cls(first.name, rows, t0, t1, qd_max, "qd, qdd as recorded, no filter", path=str(path), dof=dof,
                     effort_topic=effort_topic, block_rows=block_rows)
        source.moved, source.torque = moved, torque
        return source

    def blocks(self):
        """(signals of the block: t, q, qd, qdd, tau; the samples before it: t, qd; index of its
        first sample among the data samples) per block."""
        if self.signals is not None:
            s, keep = self.signals, _kept(self.signals)
            cut = {k: getattr(s, k)[keep] for k in ("t", "q", "qd", "qdd", "tau")}
            for a in range(0, self.rows, self.block_rows):
                part = slice(a, a + self.block_rows)
                yield SimpleNamespace(**{k: v[part] for k, v in cut.items()}), None, a
            return
        from ..data.chunks import chunks

        before, start = None, 0
        for block in chunks(self.path, self.dof, True, (), self.block_rows, self.effort_topic):
            yield block, before, start
            before, start = block, start + block.t.size

    def coulomb(self, block, before, start, smoothing, lags) -> np.ndarray:
        """(T, N): the Coulomb column of the block, as columns.coulomb_matrix of the whole recording."""
        if self.signals is not None:  # through the recording's own filter: computed whole, once a pass
            key = (tuple(np.broadcast_to(smoothing, (self.qd_max.size,))), tuple(np.broadcast_to(lags, (self.qd_max.size,))))
            if key not in self._coulomb:
                self._coulomb[key] = coulomb_matrix(self.signals, smoothing, lags)[_kept(self.signals)]
            return self._coulomb[key][start:start + block.t.size]
        if before is None:
            return coulomb_matrix(block, smoothing, lags)
        joined = SimpleNamespace(t=np.r_[before.t, block.t], qd=np.vstack([before.qd, block.qd]))
        return coulomb_matrix(joined, smoothing, lags)[before.t.size:]


def _kept(signals) -> slice:
    T = len(signals.t)
    k = int(getattr(signals, "trim", 0) or 0)
    return slice(k, T - k) if 0 < k and 2 * k < T else slice(0, T)


class Blocks:
    """Pieces (columns.Piece) of every block of every source, their label columns at the current
    settings (smoothing, lags: per joint; tilt(q) -> (T, N, 2)): iterated once per pass."""

    def __init__(self, model, sources, parts, labels, smoothing, lags, tilt=None):
        self.model, self.sources, self.parts, self.labels = model, sources, parts, labels
        self.smoothing, self.lags, self.tilt = smoothing, lags, tilt

    def __iter__(self):
        for source, part in zip(self.sources, self.parts):
            source._coulomb.clear()
            for block, before, start in source.blocks():
                yield self.piece(source, part, block, before, start)

    def fit_only(self, parts):
        """The pieces whose samples are all in `parts` (the fit's, not the --select recordings)."""
        return (p for p in self if np.isin(p.part, parts).all())

    def piece(self, source, part, block, before, start) -> Piece:
        Y = self.model.batch("regressor", block.q, block.qd, block.qdd)
        if isinstance(part, int):
            number = np.full(block.t.size, part, dtype=int)
        else:  # contiguous stretches of equal duration: columns.contiguous_parts
            u = (block.t - source.t0) / max(source.t1 - source.t0, 1e-300)
            number = np.minimum((u * part[0]).astype(int), part[0] - 1)
        p = Piece(block, slice(None), np.ascontiguousarray(Y.transpose(1, 0, 2)), np.asarray(block.tau, dtype=float),
                  number, {})
        p.source, p.start = source, start
        p.coulomb = lambda smoothing, lags: source.coulomb(block, before, start, smoothing, lags)
        coulomb = self.piece_coulomb(p) if any(k == "coulomb" for k, _ in self.labels) else None
        tilt = self.tilt(block.q) if any(k == "tilt" for k, _ in self.labels) else None
        p.columns = {lab: p.column(lab, coulomb, tilt) for lab in self.labels}
        return p

    def piece_coulomb(self, p):
        return p.coulomb(self.smoothing, self.lags)


def sources_of(recordings, block_rows: int = ROWS) -> list:
    """Sources of conditioned signals or of Sources (as they are)."""
    return [r if isinstance(r, Source) else Source.held(r, block_rows) for r in recordings]


def chained(*iterables):
    return itertools.chain(*iterables)
