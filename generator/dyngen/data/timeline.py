"""Sample times as the recording's clock took them, not as a logger stamped them (a logger stamps a
sample when it writes it: the real LWR4+ recordings have 5 ms steps with pairs of 6.5 + 3.4 ms,
which differentiated put a spike into the acceleration at every pair).

    t, note = regular(t, q)

returns the clock t0 + k T (k counted from the stamps: a dropped sample stays a gap) when every
stamp lies within JITTER_SHARE of a step from it, the stamps differ from it, and the positions'
jerk over it carries less than ROUGHER of its energy over the stamps; otherwise the stamps and None."""

from __future__ import annotations

import numpy as np

JITTER_SHARE = 0.45  # of a step: stamps further from the clock than this are not jitter
ROUGHER = 0.5  # the clock is used when the positions' jerk energy over it is below this share


def regular(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, str | None]:
    t = np.asarray(t, dtype=float)
    if t.size < 16:
        return t, None
    steps = np.diff(t)
    # ticks counted step by step (a late stamp and the early one after it are one tick each;
    # a step of two periods is a dropped sample), so that a slow drift of the stamps cannot
    # make two samples one tick
    k = np.concatenate([[0.0], np.cumsum(np.maximum(np.round(steps / np.median(steps)), 1.0))])
    # The clock's period and phase as medians: most stamps are on time, and a logger's are
    # late, never early, so a mean (a line fit) would put the clock late by their average delay.
    half = t.size // 2
    period = float(np.median((t[half:2 * half] - t[:half]) / (k[half:2 * half] - k[:half])))
    clock = float(np.median(t - k * period)) + k * period
    off = np.abs(t - clock)
    if off.max() > JITTER_SHARE * period or off.max() <= 1e-6 * period:
        return t, None
    if _roughness(clock, q) >= ROUGHER * _roughness(t, q):
        return t, None
    return clock, (f"time stamps jitter by up to {1e3 * off.max():.2g} ms around a regular {1e3 * period:.4g} ms "
                   "clock; the positions are smooth over the clock, not over the stamps: the clock is used")


def _roughness(t: np.ndarray, q: np.ndarray) -> float:
    """Median over joints of the energy of the positions' third derivative over times t."""
    jerk = np.gradient(np.gradient(np.gradient(q, t, axis=0), t, axis=0), t, axis=0)
    return float(np.median(np.sum(jerk ** 2, axis=0)))
