"""Errors of the measurement itself, as candidates of the diagnosis (the terms: terms/sensor.py).

The time shift is linear in dt only to first order, -dt * d tau_model / dt, which fails
wherever tau_model jumps (an acceleration step): the measured torque keeps the value before
the jump for dt, while the sampled derivative puts a spike of jump * dt / (2 h) on the two
samples around it (h the sample period; 5 times the jump for 10 ms at 1 kHz). So its column
is the exact form at a shift dt0,

    (tau_model(t - dt0) - tau_model(t)) / dt0       (tau_model interpolated linearly in time)

whose fitted value dt equals dt0 when the model holds. Selection tries a few variants of dt0
(TIME_SHIFTS in effects/__init__.py); once selected, dt0 is refined by fixed-point iteration
dt0 <- dt (refine.py), which also reaches negative shifts (torques leading the positions).
"""

from __future__ import annotations

from ... import terms
from .base import Effect


class Offset(Effect):
    term = terms.Offset
    simple_term = "b"
    local = sensor = True

    def columns(self, context, signals, tau_model):
        return self.term.columns(signals.q.shape)


class Gain(Effect):
    """measured = (1 + k-1) * torque: the model's torque (its column) and every other effect's
    torque on the arm alike, friction and payload included. Its setting g0 is the gain those are
    scaled by (Context.scale), refined to the fitted value once selected (0 while selecting)."""

    term = terms.Gain
    refinable = sensor = scales = shapes_others = True
    tolerance = 1e-4  # of the torque: far below any gain a diagnosis reports

    def __init__(self, gain: float = 0.0):
        self.gain = float(gain)
        self.label = f"g0={self.gain:.6g}" if self.gain else ""

    @property
    def setting(self):
        return self.gain

    def implied_setting(self, values):
        return float(values[0])

    def at(self, setting):
        return Gain(setting)

    def columns(self, context, signals, tau_model):
        return self.term.columns(tau_model)

    def derived(self, robot, values, std, torque_rms):
        return {"factor": 1.0 + values["k-1"]}


class TimeShift(Effect):
    term = terms.TimeShift
    refinable = sensor = delays = shapes_others = True

    def __init__(self, shift: float):
        self.shift = float(shift)  # dt0 [s], not 0
        self.label = f"dt0={self.shift:.6g}"

    def fixed(self):
        return {"dt0": self.shift}

    def columns(self, context, signals, tau_model):
        return self.term.columns(signals.t, tau_model, self.shift)

    @property
    def setting(self):
        return self.shift

    def implied_setting(self, values):
        return float(values[0]) or None

    def at(self, setting):
        return TimeShift(setting)

    def derived(self, robot, values, std, torque_rms):
        return {"dt_ms": 1e3 * values["dt"], "dt_std_ms": 1e3 * std["dt"]}
