"""Errors of the measurement itself.

    offset      b                                  per joint [Nm]: the torque sensor's zero
    gain        (k - 1) tau_model                  per joint [1]: the sensor reads k times the torque
    time_shift  (tau(t - dt0) - tau(t)) / dt0      whole arm [s]: torques lag the positions by dt

The time shift's column is its exact form at a shift dt0 (the first-order -dt d tau_model / dt
spikes wherever tau_model jumps), whose fitted dt equals dt0 when the model holds: the diagnosis
tries TIME_SHIFTS and refines dt0 <- dt once selected (refine.py), negative shifts included."""

from __future__ import annotations

import numpy as np

from .term import Term, Value

MAX_GAIN = 0.5  # a sensor that reads 0.5 to 1.5 times the torque
MAX_SHIFT = 0.1  # s: a longer lag between positions and torques is not a sensor's time shift


class Offset(Term):
    name, doc = "offset", "torque-sensor zero offset b"
    values = (Value("b", "Nm"),)
    simple_term = "b"
    local = sensor = True

    @staticmethod
    def regressor(shape):
        return np.ones(tuple(shape) + (1,))

    def columns(self, context, signals, tau_model):
        return self.regressor(signals.q.shape)


class Gain(Term):
    """measured = (1 + k-1) * torque: the model's torque (its column) and every other term's
    torque on the arm alike, friction and payload included. Its setting g0 is the gain those are
    scaled by (Context.scale), refined to the fitted value once selected (0 while selecting)."""

    name, doc = "gain", "torque-sensor gain: the measured torque is (1 + (k - 1)) times the arm's"
    values = (Value("k-1", "1", -MAX_GAIN, MAX_GAIN),)
    refinable = sensor = scales = shapes_others = True
    tolerance = 1e-4  # of the torque: far below any gain a diagnosis reports

    def __init__(self, gain: float = 0.0):
        self.gain = float(gain)
        self.label = f"g0={self.gain:.6g}" if self.gain else ""

    @staticmethod
    def regressor(tau_model):
        return tau_model[:, :, None]

    def columns(self, context, signals, tau_model):
        return self.regressor(tau_model)

    @property
    def setting(self):
        return self.gain

    def implied_setting(self, values):
        return float(values[0])

    def at(self, setting):
        return Gain(setting)

    def derived(self, robot, values, std, torque_rms):
        return {"factor": 1.0 + values["k-1"]}


class TimeShift(Term):
    name, scope, doc = "time_shift", "arm", "time shift: the torques lag the positions by dt"
    values = (Value("dt", "s", -MAX_SHIFT, MAX_SHIFT),)
    settings = (Value("dt0", "s"),)
    pointwise = False
    refinable = sensor = delays = shapes_others = True

    def __init__(self, shift: float):
        self.shift = float(shift)  # dt0 [s], not 0
        self.label = f"dt0={self.shift:.6g}"

    @staticmethod
    def regressor(t, tau_model, dt0: float):
        # Before the first sample the torque is held at its first value (np.interp's ends).
        shifted = np.column_stack([np.interp(t - dt0, t, tau) for tau in tau_model.T])
        return ((shifted - tau_model) / dt0)[:, :, None]

    def columns(self, context, signals, tau_model):
        return self.regressor(signals.t, tau_model, self.shift)

    def fixed(self):
        return {"dt0": self.shift}

    @property
    def setting(self):
        return self.shift

    def implied_setting(self, values):
        return float(values[0]) or None

    def at(self, setting):
        return TimeShift(setting)

    def derived(self, robot, values, std, torque_rms):
        return {"dt_ms": 1e3 * values["dt"], "dt_std_ms": 1e3 * std["dt"]}
