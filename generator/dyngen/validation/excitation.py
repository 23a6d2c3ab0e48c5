"""Excitation trajectories for identification: a finite Fourier series per joint (Swevers et al.).

Joint j with base frequency w = 2 pi f and L harmonics:

    q_j(t)   = q0_j + sum_l  a_jl / (w l) sin(w l t) - b_jl / (w l) cos(w l t)
    qd_j(t)  =        sum_l  a_jl cos(w l t) + b_jl sin(w l t)
    qdd_j(t) =        sum_l -a_jl w l sin(w l t) + b_jl w l cos(w l t)

The motion is periodic with period 1 / f and band-limited (highest frequency L f), so it can
be evaluated at any time (e.g. shifted) and filtered without edge effects over whole periods.
`fourier_excitation` draws the coefficients from a seed and scales each joint so that its
position, velocity and acceleration stay within a margin of the given limits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FourierTrajectory:
    base_hz: float
    offset: np.ndarray  # (N,) q0
    a: np.ndarray  # (N, L) velocity cosine amplitudes
    b: np.ndarray  # (N, L) velocity sine amplitudes

    def __call__(self, t):
        """q, qd, qdd (T x N) at the times t (T,)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        w = 2.0 * np.pi * self.base_hz * np.arange(1, self.a.shape[1] + 1)  # (L,)
        s, c = np.sin(np.outer(t, w)), np.cos(np.outer(t, w))  # (T, L)
        q = self.offset + s @ (self.a / w).T - c @ (self.b / w).T
        qd = c @ self.a.T + s @ self.b.T
        qdd = -s @ (self.a * w).T + c @ (self.b * w).T
        return q, qd, qdd

    def sample(self, duration: float, rate_hz: float):
        """t, q, qd, qdd on the grid 0, 1/rate, ... up to duration (included when on the grid)."""
        if duration <= 0 or rate_hz <= 0:
            raise ValueError("duration and rate_hz must be positive")
        t = np.arange(int(np.floor(duration * rate_hz + 1e-9)) + 1) / rate_hz
        return (t, *self(t))


def fourier_excitation(lower, upper, velocity, acceleration, seed: int, harmonics: int = 5,
                       base_hz: float = 0.1, margin: float = 0.9) -> FourierTrajectory:
    """A random Fourier excitation inside the limits (arrays of N; `acceleration` may be a scalar).

    The offset q0 is drawn in the middle fifth of each joint's range; the coefficients are drawn
    as standard normals divided by the harmonic number (smoother motion), then each joint is
    scaled by the largest factor that keeps |q - q0| <= margin * (distance from q0 to the nearer
    limit), |qd| <= margin * velocity and |qdd| <= margin * acceleration. The peaks are taken on
    a grid of 200 points per period of the highest harmonic (relative error below 1e-4, well
    inside the margin). Deterministic: the same arguments give the same trajectory."""
    lower, upper, velocity = (np.asarray(x, dtype=float).ravel() for x in (lower, upper, velocity))
    n = lower.size
    acceleration = np.broadcast_to(np.asarray(acceleration, dtype=float), (n,))
    if not (upper.size == velocity.size == n):
        raise ValueError("lower, upper and velocity need one entry per joint")
    for name, x in (("velocity", velocity), ("acceleration", acceleration), ("range", upper - lower)):
        if not np.all(np.isfinite(x)) or np.any(x <= 0):
            raise ValueError(f"every joint needs a finite, positive {name} limit")
    if not 0 < margin <= 1 or harmonics < 1 or base_hz <= 0:
        raise ValueError("need 0 < margin <= 1, harmonics >= 1, base_hz > 0")

    rng = np.random.default_rng(seed)
    centre, half = (upper + lower) / 2, (upper - lower) / 2
    offset = centre + rng.uniform(-0.2, 0.2, n) * half
    decay = 1.0 / np.arange(1, harmonics + 1)
    a = rng.standard_normal((n, harmonics)) * decay
    b = rng.standard_normal((n, harmonics)) * decay

    unit = FourierTrajectory(base_hz, np.zeros(n), a, b)
    grid = np.arange(200 * harmonics) / (200 * harmonics * base_hz)  # one period
    q, qd, qdd = unit(grid)
    room = margin * np.minimum(upper - offset, offset - lower)
    scale = np.min([room / np.max(np.abs(q), axis=0),
                    margin * velocity / np.max(np.abs(qd), axis=0),
                    margin * acceleration / np.max(np.abs(qdd), axis=0)], axis=0)
    return FourierTrajectory(base_hz, offset, a * scale[:, None], b * scale[:, None])


def robot_excitation(robot, seed: int, acceleration=5.0, **kw) -> FourierTrajectory:
    """fourier_excitation within a dyngen robot's joint limits (position and velocity must be given)."""
    for i, joint in enumerate(robot.joints, start=1):
        lim = joint.limits
        if lim is None or None in (lim.lower, lim.upper, lim.velocity):
            raise ValueError(f"{robot.source}: joints[{i - 1}].limits: an excitation needs lower, upper and velocity")
    lims = [j.limits for j in robot.joints]
    return fourier_excitation([l.lower for l in lims], [l.upper for l in lims], [l.velocity for l in lims],
                              acceleration, seed, **kw)
