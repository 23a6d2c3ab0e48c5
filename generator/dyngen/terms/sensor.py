"""Errors of the measurement itself.

    offset      b                                  per joint [Nm]: the torque sensor's zero
    gain        (k - 1) tau_model                  per joint [1]: the sensor reads k times the torque
    time_shift  (tau(t - dt0) - tau(t)) / dt0      whole arm [s]: torques lag the positions by dt
                                                   (the exact form at a shift dt0, fitted dt; its
                                                   columns need dt0 of samples before a chunk)
"""

from __future__ import annotations

import numpy as np

from .base import Term, Value

MAX_GAIN = 0.5  # a sensor that reads 0.5 to 1.5 times the torque
MAX_SHIFT = 0.1  # s: a longer lag between positions and torques is not a sensor's time shift


class Offset(Term):
    name, doc = "offset", "torque-sensor zero offset b"
    values = (Value("b", "Nm"),)

    @staticmethod
    def columns(shape):
        return np.ones(tuple(shape) + (1,))


class Gain(Term):
    name, doc = "gain", "torque-sensor gain: the measured torque is (1 + (k - 1)) times the arm's"
    values = (Value("k-1", "1", -MAX_GAIN, MAX_GAIN),)

    @staticmethod
    def columns(tau_model):
        return tau_model[:, :, None]


class TimeShift(Term):
    name, scope, doc = "time_shift", "arm", "time shift: the torques lag the positions by dt"
    values = (Value("dt", "s", -MAX_SHIFT, MAX_SHIFT),)
    settings = (Value("dt0", "s"),)
    pointwise = False

    @staticmethod
    def columns(t, tau_model, dt0: float):
        # Before the first sample the torque is held at its first value (np.interp's ends).
        shifted = np.column_stack([np.interp(t - dt0, t, tau) for tau in tau_model.T])
        return ((shifted - tau_model) / dt0)[:, :, None]
