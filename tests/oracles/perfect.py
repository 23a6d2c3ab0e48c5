"""What a perfect model leaves on conditioned data: the bound a diagnosis is judged against.

A diagnosis cannot do better than the simulated arm itself seen through the same conditioning:
the recording's filtered torque minus the torque MuJoCo gives (mujoco_measurements.measure:
the simulated links with every injected effect, no noise) along the *conditioned* motion,
passed through the same filter. Differentiation noise, filter smoothing and torque noise all
stay in it; only the effects' absence does not. Nothing here uses dyngen's models.
"""

from __future__ import annotations

import numpy as np

from dataclasses import replace

from .mujoco_measurements import Trajectory, measure


def perfect_residual(robot, p_true, effects, signals, friction=None) -> np.ndarray:
    """(T, N) residual of the perfect model on one conditioned recording (dyngen.data.Signals).
    friction: for a tracked recording (mujoco_tracking.py), the friction torque the simulation
    produced at each sample (its stick phases cannot be recomputed from the motion)."""
    t = signals.t

    def at(times):
        times = np.clip(times, t[0], t[-1])
        return tuple(np.column_stack([np.interp(times, t, x[:, j]) for j in range(x.shape[1])])
                     for x in (signals.q, signals.qd, signals.qdd))

    if friction is None:
        tau = measure(robot, p_true, Trajectory(t, at), effects, noise=0.0).tau
    else:
        rigid = replace(effects, coulomb={}, viscous={}, stribeck={}, gain={}, offset={})
        tau = measure(robot, p_true, Trajectory(t, at), rigid, noise=0.0).tau + friction
        for i, g in effects.gain.items():
            tau[:, i - 1] *= 1.0 + g
        for i, o in effects.offset.items():
            tau[:, i - 1] += o
    return signals.tau - signals.filtered(tau)


def perfect_rms(robot, p_true, effects, signals, friction=None) -> np.ndarray:
    r = perfect_residual(robot, p_true, effects, signals, friction)[signals.inner()]
    return np.sqrt(np.mean(r ** 2, axis=0))
