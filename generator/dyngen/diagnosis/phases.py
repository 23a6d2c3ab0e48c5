"""Where in the motion a residual lives: per joint, every sample gets phase labels (several may
apply): standstill (|qd| < still), reversal (within `window` of a sign change of qd between
motions), slow / fast (below / above half the largest |qd|), accelerating (|qdd| above half the
largest), and the low / middle / high third of the positions."""

from __future__ import annotations

import numpy as np

PHASES = ("standstill", "reversal", "slow", "fast", "accelerating", "low range", "middle range", "high range")


def labels(t, q, qd, qdd, still: float = 0.02, window: float = 0.15) -> dict:
    """name -> boolean (T, N) mask."""
    T, n = q.shape
    speed = np.abs(qd)
    moving = speed >= still
    vmax = np.maximum(speed.max(axis=0), still)
    amax = np.maximum(np.abs(qdd).max(axis=0), 1e-12)
    reversal = np.column_stack([_near_reversals(t, qd[:, j], moving[:, j], window) for j in range(n)])
    lo, hi = np.quantile(q, [1 / 3, 2 / 3], axis=0)
    return {
        "standstill": ~moving,
        "reversal": reversal,
        "slow": moving & (speed < 0.5 * vmax),
        "fast": speed >= 0.5 * vmax,
        "accelerating": np.abs(qdd) >= 0.5 * amax,
        "low range": q <= lo,
        "middle range": (q > lo) & (q < hi),
        "high range": q >= hi,
    }


def by_phase(residual: np.ndarray, masks: dict) -> list[dict]:
    """Per joint: {phase: {"rms", "share"}} and the phase where the RMS stands out most."""
    out = []
    for j in range(residual.shape[1]):
        total = float(np.sqrt(np.mean(residual[:, j] ** 2)))
        phases = {name: {"rms": float(np.sqrt(np.mean(residual[mask[:, j], j] ** 2))), "share": float(mask[:, j].mean())}
                  for name, mask in masks.items() if mask[:, j].any()}
        # The phase with the largest RMS among those with a fair share of samples (>= 5 %).
        fair = {k: v for k, v in phases.items() if v["share"] >= 0.05}
        worst = max(fair, key=lambda k: fair[k]["rms"]) if fair else None
        ratio = fair[worst]["rms"] / total if worst and total > 0 else 1.0
        out.append({"joint": j + 1, "rms": total, "peak": float(np.abs(residual[:, j]).max()),
                     "mean": float(residual[:, j].mean()), "phases": phases, "worst_phase": worst,
                     "worst_ratio": float(ratio)})
    return out


def _near_reversals(t, v, moving, window) -> np.ndarray:
    """Samples within `window` of a reversal: moving samples of opposite sign at most 2 windows apart."""
    idx = np.flatnonzero(moving)
    flips = np.flatnonzero((np.sign(v[idx[1:]]) != np.sign(v[idx[:-1]])) & (t[idx[1:]] - t[idx[:-1]] <= 2 * window))
    times = 0.5 * (t[idx[flips]] + t[idx[flips + 1]])
    marks = np.zeros(t.size + 1, dtype=int)
    np.add.at(marks, np.searchsorted(t, times - window, side="left"), 1)
    np.add.at(marks, np.searchsorted(t, times + window, side="right"), -1)
    return np.cumsum(marks[:-1]) > 0
