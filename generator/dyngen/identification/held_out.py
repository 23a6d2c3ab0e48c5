"""Choices made on held-out data (the `select` recordings, or each contiguous part of the fit data
once), never on test data: the prior's weight lambda (the one-standard-error rule) and which optional
column groups stay (a gain over one standard error of the paired differences): docs/measured-data.md."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Folds:
    """(fit parts, held-out parts) per fold, and the per-joint weights of every score."""

    splits: list
    weights: np.ndarray

    @classmethod
    def make(cls, parts: int, select: bool, weights) -> "Folds":
        if select:  # parts 0 .. parts - 2 are fit data, the last one the select recordings
            return cls([(list(range(parts - 1)), [parts - 1])], np.asarray(weights))
        return cls([([q for q in range(parts) if q != k], [k]) for k in range(parts)], np.asarray(weights))


@dataclass
class Scores:
    weighted: np.ndarray  # (folds,) weighted held-out mean square
    joints: np.ndarray  # (folds, N) per joint held-out mean square
    free: list = field(default_factory=list)  # the active sets the fits ended with (warm starts)


def scores(solver, normal, folds: Folds, labels_idx, lam: float, free=None, workers: int = 1, cone=()) -> Scores:
    """Each fold's consistent fit of the coefficients and labels_idx at lam, scored on its held-out parts."""
    r = normal.r
    keep = np.r_[np.arange(r), r + np.asarray(labels_idx, dtype=int)]
    labels = [normal.labels[k] for k in labels_idx]
    w2 = folds.weights ** 2

    def one(k):
        fit, held = folds.splits[k]
        G, g = normal.total(fit, folds.weights, keep)
        x, f, _ = solver.solve(G, g, labels, lam, restarts=1, free=None if free is None else free[k], cone=cone)
        sse = normal.sse(x, held, keep).sum(axis=0)
        n = normal.n[held].sum(axis=0)
        return float(sse @ w2 / max(n.sum(), 1.0)), sse / np.maximum(n, 1), f

    if workers > 1 and len(folds.splits) > 1:
        with ThreadPoolExecutor(max_workers=workers) as pool:
            out = list(pool.map(one, range(len(folds.splits))))
    else:
        out = [one(k) for k in range(len(folds.splits))]
    return Scores(np.array([o[0] for o in out]), np.array([o[1] for o in out]), [o[2] for o in out])


def choose_lambda(solver, normal, folds: Folds, labels_idx, grid, rule: str = "1se", workers: int = 1, cone=()):
    """(lambda, [(lambda, mean weighted score)], {lambda: Scores})."""
    table, kept, free = [], {}, None
    for lam in sorted(grid):
        s = scores(solver, normal, folds, labels_idx, lam, free, workers, cone)
        free = s.free
        kept[lam] = s
        table.append((float(lam), float(s.weighted.mean())))
        means = np.array([m for _, m in table])
        best = int(np.argmin(means))
        limit = means[best] + _se(kept[table[best][0]].weighted)
        if len(table) - 1 > best and means[-1] > limit:
            break
    chosen = max(i for i in range(len(means)) if means[i] <= limit) if rule == "1se" and len(folds.splits) > 1 else best
    return table[chosen][0], table, kept


def _se(x: np.ndarray) -> float:
    return float(x.std(ddof=1) / np.sqrt(x.size)) if x.size > 1 else 0.0


def gains(with_group: Scores, without: Scores, joint: int | None = None) -> tuple[float, float, float]:
    """(mean gain, its standard error, the mean score without the group) over the folds (joint's score)."""
    a, b = (without.weighted, with_group.weighted) if joint is None else (without.joints[:, joint],
                                                                          with_group.joints[:, joint])
    d = a - b
    return float(d.mean()), _se(d), float(a.mean())


SMALLEST_GAIN = 1e-3  # relative to the score without the group: below it, two fits that are the same


def keeps(gain: tuple[float, float, float], folds: Folds) -> bool:
    """The group stays when it gains by more than one standard error (one split: at all) and SMALLEST_GAIN."""
    mean, se, reference = gain
    return mean > (se if len(folds.splits) > 1 else 0.0) and mean > SMALLEST_GAIN * reference
