"""Errors of the measurement itself.

    offset:      b                                  per joint [Nm]: torque-sensor zero offset
    gain:        (k - 1) * tau_model                per joint [1]: the sensor reads k times the torque
    time shift:  tau(t - dt) - tau(t)               whole arm [s]: torques lag positions by dt

The time shift is selected to first order, -dt * d tau_model / dt, which holds only where
tau_model is smooth over dt: where it jumps (an acceleration step), the measured torque keeps
the value before the jump for dt, and the derivative cannot say so. Once selected, the shift
is refined (refine.py) with the exact form at a shift dt0, (tau_model(t - dt0) - tau_model(t))
/ dt0, tau_model interpolated linearly between samples, so that the fitted dt equals dt0 when
the model holds.
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
    refinable = True

    def __init__(self, shift: float = 0.0):
        self.shift = float(shift)  # dt0 [s]; 0: first order
        self.label = f"dt0={self.shift:.6g}" if self.shift else ""

    def fixed(self):
        return {"dt0": self.shift} if self.shift else {}

    def columns(self, context, signals, tau_model):
        if not self.shift:
            return -np.gradient(tau_model, signals.t, axis=0)[:, :, None]
        # Before the first sample the torque is held at its first value (np.interp's ends).
        shifted = np.column_stack([np.interp(signals.t - self.shift, signals.t, tau) for tau in tau_model.T])
        return ((shifted - tau_model) / self.shift)[:, :, None]

    @property
    def setting(self):
        return self.shift

    def implied_setting(self, values):
        return float(values[0]) or None

    def at(self, setting):
        return TimeShift(setting)
