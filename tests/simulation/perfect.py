"""What a perfect model leaves on conditioned data: the bound a diagnosis is judged against.

The perfect model is the simulated arm with exactly the injected effects, as laws: the torque
MuJoCo gives (mujoco_measurements.measure: the simulated links, every injected effect, no noise;
Coulomb friction as Fc sign(qd)) along the *conditioned* motion, passed through the same filter,
subtracted from the recording's filtered torque. Differentiation noise, filter smoothing and
torque noise stay in it; so do, for tracked recordings (mujoco_tracking.py), the stick phases,
where friction takes whatever value between -Fc and Fc holds the joint: no law of the motion
predicts it, the perfect model's included. Nothing here uses dyngen's models.
"""

from __future__ import annotations

import numpy as np

from .mujoco_measurements import Trajectory, measure


def perfect_residual(robot, p_true, effects, signals) -> np.ndarray:
    """(T, N) residual of the perfect model on one conditioned recording (dyngen.data.Signals)."""
    t = signals.t

    def at(times):
        times = np.clip(times, t[0], t[-1])
        return tuple(np.column_stack([np.interp(times, t, x[:, j]) for j in range(x.shape[1])])
                     for x in (signals.q, signals.qd, signals.qdd))

    tau = measure(robot, p_true, Trajectory(t, at), effects, noise=0.0).tau
    return signals.tau - signals.filtered(tau)


def perfect_rms(robot, p_true, effects, signals) -> np.ndarray:
    r = perfect_residual(robot, p_true, effects, signals)[signals.inner()]
    return np.sqrt(np.mean(r ** 2, axis=0))
