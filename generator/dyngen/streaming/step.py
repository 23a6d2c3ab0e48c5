"""The per-recording step of identification by least squares: read one recording in blocks,
evaluate the generated regressor on each block and fold its rows into per-joint triangular
factors (identification/triangular.py). What it returns is (c+1)^2 numbers per joint, whatever the
recording's length; the step runs in a worker process or on a Dask worker (engine.py), so its
task and result are plain picklable data.

The blocks are conditioned on their own when that is what conditioning the whole recording
would do: the recording has qd and qdd columns and the conditioning is automatic or no filter
(then the signals are the recorded columns, data/conditioning.py). Otherwise (positions to
differentiate, a low-pass filter: zero-phase filters and the automatic cutoff need the whole
recording) the recording is read and conditioned whole, then folded in blocks: the same
result, with memory of one recording.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass, field

import numpy as np

from ..identification.samples import regressor_rows
from ..identification.triangular import Triangular

KINDS = ("full", "gravity", "inertia")


@dataclass(frozen=True)
class Task:
    path: str
    dof: int
    kind: str  # "full", "gravity" or "inertia"
    folder: str  # the generated, compiled model
    conditioning: object  # data.Conditioning
    required: tuple = ()  # the stacked inertia columns, for kind inertia
    bag: object = None  # data.rosbag.BagReading: how a ROS 2 bag is read (None: its defaults)
    rows: int = 8192  # samples per block


@dataclass
class Sums:
    name: str
    factors: Triangular  # per joint (per stacked inertia entry for kind inertia)
    samples: int
    note: str  # what conditioning did
    streamed: bool  # read in blocks (memory independent of the length) or whole
    warnings: list = field(default_factory=list)


@functools.lru_cache(maxsize=4)
def _model(folder: str):
    from ..runtime import load

    return load(folder)


def _local(first, conditioning) -> bool:
    from ..data.conditioning import AUTO

    return first.qd is not None and first.qdd is not None and not conditioning.differentiate \
        and conditioning.cutoff in (AUTO, None)


def run(task: Task) -> Sums:
    from ..data import condition, read_recording
    from ..data.chunks import chunks
    from ..data.log_quality import Streamed

    model = _model(task.folder)
    need_tau = task.kind != "inertia"
    blocks = chunks(task.path, task.dof, need_tau, task.required, task.rows, task.bag)
    first = next(blocks)
    factors, samples = None, 0

    def add(q, qd, qdd, tau, extra):
        nonlocal factors, samples
        Y, b = regressor_rows(model, task.kind, q, qd, qdd, tau, extra)
        if factors is None:
            factors = Triangular(Y.shape[-1], Y.shape[1])
        factors.add(Y, b)
        samples += q.shape[0]

    if _local(first, task.conditioning):
        log = Streamed()  # repeated rows left out as data.conditioning does
        for piece in log.blocks(itertools.chain([first], blocks)):  # one block at a time, never all
            add(piece.q, piece.qd, piece.qdd, piece.tau, piece.extra)
        note = "; ".join(log.report.notes + ["qd, qdd as recorded, no filter"])
        return Sums(first.name, factors, samples, note, True, log.report.warnings)
    blocks.close()
    s = condition(read_recording(task.path, task.dof, need_tau, task.required, task.bag),
                  task.conditioning)
    kept = np.flatnonzero(s.inner())  # not the filter's start-up at the ends, nor samples invented in a long gap
    for a in range(0, kept.size, task.rows):
        cut = kept[a:a + task.rows]
        add(s.q[cut], s.qd[cut], s.qdd[cut], None if s.tau is None else s.tau[cut],
            {k: v[cut] for k, v in s.extra.items()})
    return Sums(s.name, factors, samples, s.note, False, list(s.warnings))
