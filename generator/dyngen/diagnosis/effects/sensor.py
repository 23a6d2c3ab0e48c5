"""Errors of the measurement itself.

    offset:      b                                  per joint [Nm]: torque-sensor zero offset
    gain:        (k - 1) * tau_model                per joint [1]: the sensor reads k times the torque
    time shift:  tau(t - dt) - tau(t) ~ -dt * d tau_model / dt   whole arm [s]: torques lag positions by dt
"""

from __future__ import annotations

import numpy as np

from .base import Effect


class Offset(Effect):
    name, parameters, units = "offset", ("b",), ("Nm",)

    def columns(self, context, signals, tau_model):
        return np.ones(signals.q.shape + (1,))


class Gain(Effect):
    name, parameters, units = "gain", ("k-1",), ("1",)

    def plausible(self, values):
        return bool(np.all(np.abs(values) < 0.5))  # a sensor that reads 0.5 to 1.5 times the torque

    def columns(self, context, signals, tau_model):
        return tau_model[:, :, None]


class TimeShift(Effect):
    name, scope, parameters, units = "time_shift", "arm", ("dt",), ("s",)

    def columns(self, context, signals, tau_model):
        # First order in dt: a delay of dt of the torque signal. Good for dt well below the
        # time scale of the motion (a few samples).
        return -np.gradient(tau_model, signals.t, axis=0)[:, :, None]
