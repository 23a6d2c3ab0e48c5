"""The measured-model gap per recording, in blocks and in parallel (`dyngen diagnose --survey`):
for many recordings of one arm type, is the gap the same on every robot, and which one differs?

Per recording and joint j, the gap r_j = tau_j - rnea_j(q, qd, qdd; p) with the given link
parameters p, and the simple model of diagnosis/baseline.py (offset b + Coulomb Fc tanh(qd/0.02)
+ viscous Fv qd, per joint) accumulated as triangular factors of [1, tanh(qd/0.02), qd | r_j]
(identification/triangular.py): the gap's RMS and mean, and the simple model's fit, each recording's own and
the pooled one, with its residual on every recording, come from 4 x 4 numbers per joint.
The blocks are conditioned as step.py does (recorded qd, qdd and no filter: blocks; else the
recording whole, the tanh column through its filter as in diagnosis/baseline.py).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..terms.simple_model import VELOCITY  # rad/s: the simple model's tanh scale
from . import engine
from .step import _local, _model
from ..identification.triangular import fold


@dataclass(frozen=True)
class GapTask:
    path: str
    dof: int
    folder: str
    p: tuple  # link parameters (the diagnosis' dynamic parameters)
    conditioning: object
    bag: object = None  # data.rosbag.BagReading: how a ROS 2 bag is read (None: its defaults)
    rows: int = 8192


@dataclass
class Gap:
    name: str
    factors: list  # per joint, the (4, 4) factor of [1, tanh(qd/0.02), qd | r]
    rows: int
    total: np.ndarray  # (N,): sum of r
    squares: np.ndarray  # (N,): sum of r^2
    streamed: bool


class Sums:
    """The gap's sums and the simple model's factors, block by block."""

    def __init__(self, model, p, dof: int):
        self.model, self.s = model, p
        self.factors = [None] * dof
        self.rows, self.total, self.squares = 0, np.zeros(dof), np.zeros(dof)

    @classmethod
    def start(cls, model, p, dof: int) -> "Sums":
        from ..catalogue import STANDARD_FROM_DYNAMIC

        return cls(model, model(STANDARD_FROM_DYNAMIC.name, np.asarray(p, dtype=float)), dof)

    def add(self, q, qd, qdd, tau, tanh) -> None:
        from ..catalogue import RNEA

        r = tau - self.model.batch(RNEA.name, q, qd, qdd, self.s)
        for j in range(len(self.factors)):
            self.factors[j] = fold(self.factors[j], np.column_stack([np.ones(r.shape[0]), tanh[:, j], qd[:, j],
                                                                     r[:, j]]))
        self.rows += r.shape[0]
        self.total += r.sum(axis=0)
        self.squares += (r ** 2).sum(axis=0)

    def result(self, name: str, streamed: bool) -> Gap:
        return Gap(name, self.factors, self.rows, self.total, self.squares, streamed)


def run(task: GapTask) -> Gap:
    from ..data import condition, read_recording
    from ..data.chunks import chunks
    from ..data.log_quality import Streamed

    sums = Sums.start(_model(task.folder), task.p, task.dof)
    blocks = chunks(task.path, task.dof, True, (), task.rows, task.bag)
    first = next(blocks)
    if _local(first, task.conditioning):
        for piece in Streamed().blocks(itertools.chain([first], blocks)):  # one block at a time, repeats left out
            sums.add(piece.q, piece.qd, piece.qdd, piece.tau, np.tanh(piece.qd / VELOCITY))
        return sums.result(first.name, True)
    blocks.close()
    sig = condition(read_recording(task.path, task.dof, True, (), task.bag), task.conditioning)
    keep = sig.inner()  # the filter's start-up is not data (as in the diagnosis)
    tanh = sig.filtered(np.tanh(sig.qd / VELOCITY))
    index = np.flatnonzero(keep)
    for a in range(0, index.size, task.rows):
        k = index[a:a + task.rows]
        sums.add(sig.q[k], sig.qd[k], sig.qdd[k], sig.tau[k], tanh[k])
    return sums.result(sig.name, False)


@dataclass
class Survey:
    gaps: list  # Gap per recording
    simple: np.ndarray  # (N, 3): the pooled simple model's b, Fc, Fv
    rms: np.ndarray  # (recordings, N): the gap's RMS (nominal model)
    mean: np.ndarray  # (recordings, N): its mean
    rms_simple: np.ndarray  # (recordings, N): after the pooled simple model
    rms_own: np.ndarray  # (recordings, N): after each recording's own simple model
    pooled_rms: np.ndarray  # (N,): the gap's RMS over all recordings
    pooled_simple: np.ndarray  # (N,): after the pooled simple model, over all

    def differs(self, stands_out: float) -> list:
        """[(name, joints)]: recordings whose gap RMS over the joints is more than stands_out times
        the median over recordings (three or more), with the joints where it is."""
        if len(self.gaps) < 3:
            return []
        overall = np.sqrt(np.mean(self.rms ** 2, axis=1))
        median = np.median(self.rms, axis=0)
        out = []
        for g, total, rms in zip(self.gaps, overall, self.rms):
            if total > stands_out * np.median(overall):
                joints = [j for j in range(rms.size) if rms[j] > stands_out * median[j]]
                out.append((g.name, joints or [int(np.argmax(rms / np.maximum(median, 1e-300)))]))
        return out


def _solve(R) -> np.ndarray:
    """The least-squares x of a [A | b] factor (minimum norm where A is deficient)."""
    return np.linalg.lstsq(R[:, :-1], R[:, -1], rcond=1e-12)[0]


def _rms(R, x, rows) -> float:
    return float(np.sqrt(np.sum((R @ np.r_[x, -1.0]) ** 2) / max(rows, 1)))


def survey(tasks: list, workers=None, scheduler=None) -> Survey:
    gaps = engine.run_all(run, tasks, workers, scheduler)
    n = tasks[0].dof
    pooled = [fold(None, np.vstack([g.factors[j] for g in gaps])) for j in range(n)]
    simple = np.array([_solve(R) for R in pooled])
    rows = sum(g.rows for g in gaps)
    rms = np.array([np.sqrt(g.squares / g.rows) for g in gaps])
    mean = np.array([g.total / g.rows for g in gaps])
    after = np.array([[_rms(g.factors[j], simple[j], g.rows) for j in range(n)] for g in gaps])
    own = np.array([[_rms(g.factors[j], _solve(g.factors[j]), g.rows) for j in range(n)] for g in gaps])
    pooled_rms = np.sqrt(sum(g.squares for g in gaps) / rows)
    pooled_simple = np.array([_rms(pooled[j], simple[j], rows) for j in range(n)])
    return Survey(gaps, simple, rms, mean, after, own, pooled_rms, pooled_simple)


def table(result: Survey, stands_out: float = 1.5) -> list[str]:
    n = result.rms.shape[1]
    width = max(max(len(g.name) for g in result.gaps), len("all (pooled)"))
    head = " " * width + "  " + "  ".join(f"{f'J{j + 1}':>22}" for j in range(n))
    lines = ["gap per recording, RMS [Nm] per joint: nominal model (mean) -> after the pooled simple model "
             "[its own simple model]", head]
    for g, rms, mean, after, own in zip(result.gaps, result.rms, result.mean, result.rms_simple, result.rms_own):
        lines.append(f"{g.name:<{width}}  " + "  ".join(f"{r:.3g} ({m:+.2g}) -> {a:.3g} [{o:.3g}]".rjust(22)
                                                      for r, m, a, o in zip(rms, mean, after, own)))
    lines.append(f"{'all (pooled)':<{width}}  " + "  ".join(f"{r:.3g} -> {a:.3g}".rjust(22) for r, a in
                                                           zip(result.pooled_rms, result.pooled_simple)))
    lines.append("pooled simple model (b, Fc, Fv) per joint: " + "; ".join(
        f"J{j + 1} {b:+.3g}, {c:+.3g}, {v:+.3g}" for j, (b, c, v) in enumerate(result.simple)))
    if len(result.gaps) >= 3:
        out = result.differs(stands_out)
        lines.append("differs: " + ("; ".join(f"{name} on {', '.join(f'J{j + 1}' for j in js)}" for name, js in out)
                                   if out else f"none (no recording's gap above {stands_out:g}x the median)"))
    return lines
