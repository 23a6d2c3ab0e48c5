"""Samples that a sensor or its link got wrong, found in the rows as logged (before the clock and the
filter, data/log_quality.py): positions that wrap at +-pi (a continuous joint logged in [-pi, pi)
or [0, 2 pi)), and spikes: one sample far off the line through its two neighbours while they
agree with each other (a bus error, a torque sensor's glitch). No motion makes either: a joint
does not turn by pi in one sample, and a spike is a step up and back down at once, where a real
change (a friction step at a reversal, a held column's update) stays at its new level.

    x, said = repaired(recording)      # said: what was found, in words (empty when nothing)"""

from __future__ import annotations

import dataclasses

import numpy as np

SPIKE_SIGMAS = 12.0  # off the neighbours' line by this many robust sigmas of that distance ...
SPIKE_TAIL = 4.0  # ... and by this many times its 99th percentile (spikes are rarer than 1 %) ...
NEIGHBOURS_AGREE = 0.25  # ... while the neighbours differ by at most this share of it


def spikes(x: np.ndarray) -> np.ndarray:
    """Boolean (T, N): the samples of x (T, N) that are spikes (see the module's note)."""
    x = np.asarray(x, dtype=float)
    out = np.zeros(x.shape, dtype=bool)
    if x.shape[0] < 16:
        return out
    off = x[1:-1] - 0.5 * (x[:-2] + x[2:])  # from the line through the neighbours
    size = np.abs(off)
    sigma = 1.4826 * np.median(np.abs(off - np.median(off, axis=0)), axis=0)
    tail = np.percentile(size, 99, axis=0)
    bound = np.maximum(SPIKE_SIGMAS * sigma, SPIKE_TAIL * tail)
    agree = np.abs(x[2:] - x[:-2]) <= NEIGHBOURS_AGREE * size
    out[1:-1] = (size > bound) & agree & (bound > 0)
    out[1:-1] &= ~(out[:-2] | out[2:])  # a pair of neighbours both off is no spike of one sample
    return out


def wraps(q: np.ndarray) -> list:
    """The joints whose positions jump by about 2 pi between samples and are smooth once unwrapped."""
    step = np.abs(np.diff(q, axis=0))
    out = []
    for j in np.flatnonzero(np.any(step > np.pi, axis=0)):
        smooth = np.abs(np.diff(np.unwrap(q[:, j]), axis=0))
        if smooth.max() < 0.25 * np.pi:
            out.append(int(j))
    return out


def repaired(r):
    """(the Recording with wrapped positions unwrapped and spikes in q and tau replaced by their
    neighbours' mean, notes in words)."""
    notes = []
    q = r.q
    wrapped = wraps(q)
    if wrapped:
        q = q.copy()
        q[:, wrapped] = np.unwrap(q[:, wrapped], axis=0)
        notes.append(f"positions of joint(s) {_joints(wrapped)} wrap around a full turn (an angle logged in "
                     "[-pi, pi) or [0, 2 pi)): unwrapped")
    changes = {"q": q}
    for name, x in (("q", q), ("tau", r.tau)):
        if x is None:
            continue
        x, joints = despiked(x)
        if joints.size:
            changes[name] = x
            notes.append(f"{joints.size} spike(s) in {name} (joint(s) {_joints(np.unique(joints))}: one sample off "
                         "while its neighbours agree) replaced by their neighbours' mean")
    return dataclasses.replace(r, **changes), notes


def despiked(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x with its spikes replaced by their neighbours' mean, the joint of each spike)."""
    rows, joints = np.nonzero(spikes(x))
    if rows.size:
        x = np.array(x, dtype=float)
        x[rows, joints] = 0.5 * (x[rows - 1, joints] + x[rows + 1, joints])
    return x, joints


def _joints(js) -> str:
    return ", ".join(str(int(j) + 1) for j in js)
