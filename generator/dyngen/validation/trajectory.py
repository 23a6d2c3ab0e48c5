"""Joint trajectories for validation: cubic segments through knots with zero velocity at every knot.

Between knots q0 (time t0) and q1 (time t1), with T = t1 - t0 and s = (t - t0) / T,

    q   = q0 + (q1 - q0) b(s),   b(s) = 3 s^2 - 2 s^3
    qd  = (q1 - q0) 6 s (1 - s) / T
    qdd = (q1 - q0) (6 - 12 s) / T^2

so q and qd are continuous, qd = 0 at every knot, and qdd jumps at the interior knots.
"""

from __future__ import annotations

import numpy as np

# Table V of Gaz, Flacco, De Luca (ICRA 2016): 8 knots, 7 cubic segments, 7 joints.
_H, _Q = np.pi / 2, np.pi / 4
_ALT = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0])
TABLE_V_KNOTS = np.array([
    np.full(7, _H),   # q1 = (pi/2, ..., pi/2)
    np.zeros(7),      # q2 = 0
    np.full(7, _H),   # q3 = (pi/2, ..., pi/2)
    np.full(7, -_H),  # q4 = -(pi/2, ..., pi/2)
    np.full(7, _H),   # q5 = (pi/2, ..., pi/2)
    _Q * _ALT,        # q6 = (pi/4, -pi/4, pi/4, ...)
    -_Q * _ALT,       # q7 = (-pi/4, pi/4, -pi/4, ...)
    _Q * _ALT,        # q8 = (pi/4, -pi/4, pi/4, ...)
])
TABLE_V_TIMES = np.array([0.0, 5.0, 8.0, 15.0, 22.0, 24.0, 25.5, 28.0])
TABLE_V = (TABLE_V_KNOTS, TABLE_V_TIMES)


def cubic_through_knots(knots, times, rate_hz: float = 100.0):
    """Concatenated rest-to-rest cubics through knots (K x N) at times (K,), sampled at rate_hz.

    Samples are t0 + k / rate_hz up to the last knot time, plus every knot time (a grid point
    within 1e-9 s of a knot is replaced by the knot time, so each knot is hit exactly).
    At an interior knot the sample belongs to the segment that starts there (the acceleration
    is right-continuous there); the last knot belongs to the last segment.
    Returns t (T,), q, qd, qdd (T x N).
    """
    knots = np.atleast_2d(np.asarray(knots, dtype=float))
    times = np.asarray(times, dtype=float).ravel()
    if knots.shape[0] != times.size or times.size < 2:
        raise ValueError(f"need at least 2 knots, one time each: got {knots.shape[0]} knots, {times.size} times")
    if np.any(np.diff(times) <= 0):
        raise ValueError("knot times must increase strictly")
    if rate_hz <= 0:
        raise ValueError("rate_hz must be positive")
    grid = times[0] + np.arange(int(np.floor((times[-1] - times[0]) * rate_hz + 1e-9)) + 1) / rate_hz
    near = np.min(np.abs(grid[:, None] - times[None, :]), axis=1) < 1e-9
    t = np.union1d(grid[~near], times)

    seg = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
    t0, T = times[seg], times[seg + 1] - times[seg]
    s = np.clip((t - t0) / T, 0.0, 1.0)
    s[t == times[seg + 1]] = 1.0  # the last knot exactly
    q0, q1 = knots[seg], knots[seg + 1]
    delta = q1 - q0
    b = (s * s * (3.0 - 2.0 * s))[:, None]
    q = (1.0 - b) * q0 + b * q1  # exactly q0 at s = 0 and q1 at s = 1
    qd = delta * (6.0 * s * (1.0 - s) / T)[:, None]
    qdd = delta * ((6.0 - 12.0 * s) / T**2)[:, None]
    return t, q, qd, qdd


def table_v(rate_hz: float = 100.0):
    """The paper's Table V trajectory: (t, q, qd, qdd), 0 to 28 s, 7 joints."""
    return cubic_through_knots(TABLE_V_KNOTS, TABLE_V_TIMES, rate_hz)
