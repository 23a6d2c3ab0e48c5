"""Least squares over many recordings: each recording's factors from its own step (in
parallel, step.py on engine.py), then the pooled fit and, per recording, its own fit and the
pooled fit's residual on it: is the gap the same on every robot, and which one differs?

    result = identify_recordings(tasks, names, workers=2)     # Pooled
    result.estimate                     # the fit on every recording: identification.Estimate
    result.rms_pooled[i, j]             # its residual RMS on recording i, joint j
    result.rms_own[i, j]                # recording i's own fit's residual there
    result.differs()                    # [(recording, joints)] whose residual stands out
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from . import engine, step
from ..identification.least_squares import fit_factor
from ..identification.triangular import Triangular

STANDS_OUT = 1.5  # a recording differs when the pooled fit's residual on it is this many times the median


@dataclass
class Pooled:
    estimate: object  # identification.Estimate of all rows
    sums: list  # step.Sums per recording, in the given order
    rms_pooled: np.ndarray  # (recordings, rows per sample): the pooled fit's residual RMS
    rms_own: np.ndarray  # (recordings, rows per sample): each recording's own fit's (nan: too few rows)

    def overall(self) -> np.ndarray:
        """(recordings,): the pooled fit's residual RMS over all of each recording's rows."""
        rows = np.array([s.factors.rows for s in self.sums], dtype=float)
        return np.sqrt(np.sum(self.rms_pooled ** 2 * rows, axis=1) / np.maximum(rows.sum(axis=1), 1))

    def differs(self) -> list:
        """[(recording name, [row indices])]: the recordings whose residual RMS under the pooled fit
        is more than STANDS_OUT times the median over the recordings (three recordings or more;
        a median, so that one robot unlike the others cannot hide by pulling the pooled fit), and
        the joints where its residual is more than STANDS_OUT times that joint's median (else its
        largest)."""
        if len(self.sums) < 3:
            return []
        overall = self.overall()
        median = np.median(self.rms_pooled, axis=0)
        out = []
        for s, total, rms in zip(self.sums, overall, self.rms_pooled):
            if total > STANDS_OUT * np.median(overall):
                joints = [j for j in range(rms.size) if rms[j] > STANDS_OUT * median[j]]
                out.append((s.name, joints or [int(np.argmax(rms / np.maximum(median, 1e-300)))]))
        return out


def identify_recordings(tasks: list, names: list, workers=None, scheduler=None) -> Pooled:
    sums = engine.run_all(step.run, tasks, workers, scheduler)
    total = sums[0].factors
    for s in sums[1:]:
        total = total.merged(s.factors)
    rows = int(total.rows.sum())
    kind = tasks[0].kind
    if rows <= total.c:
        files = ", ".join(s.name for s in sums)
        per_sample = total.dof
        raise InputError(files, "", f"under-determined: {rows} equations for {total.c} {kind} coefficients; record "
                         f"at least {total.c // per_sample + 1} samples (many more, on an exciting trajectory, "
                         "for a usable estimate)")
    try:
        estimate = fit_factor(total.factor(), rows, names)
    except np.linalg.LinAlgError as err:
        raise InputError(", ".join(s.name for s in sums), "", f"least squares failed ({err}); check the recordings "
                         "for extreme values") from None
    pooled = np.array([np.sqrt(s.factors.sse(estimate.values) / np.maximum(s.factors.rows, 1)) for s in sums])
    own = np.array([_own(s.factors, names) for s in sums])
    return Pooled(estimate, sums, pooled, own)


def _own(factors: Triangular, names) -> np.ndarray:
    rows = int(factors.rows.sum())
    if rows <= factors.c or len(names) == 0:
        return np.full(factors.dof, np.nan)
    x = fit_factor(factors.factor(), rows, names).values
    return np.sqrt(factors.sse(x) / np.maximum(factors.rows, 1))


def table(result: Pooled, row_names: list) -> list[str]:
    """Lines of the per-recording table: residual RMS per row (joint) of the pooled fit, and
    the recording's own fit in parentheses; then which recordings stand out."""
    width = max(len(s.name) for s in result.sums)
    lines = ["residual RMS per recording: pooled fit (the recording's own fit)",
             " " * width + "  " + "  ".join(f"{n:>15}" for n in row_names)]
    for s, pooled, own in zip(result.sums, result.rms_pooled, result.rms_own):
        lines.append(f"{s.name:<{width}}  " + "  ".join(f"{p:8.4g} ({o:.3g})".rjust(15) for p, o in zip(pooled, own)))
    if len(result.sums) >= 3:
        out = result.differs()
        lines.append("differs: " + ("; ".join(f"{n} on {', '.join(row_names[j] for j in js)}" for n, js in out)
                                   if out else f"none (no recording's residual above {STANDS_OUT:g}x the median)"))
    return lines
