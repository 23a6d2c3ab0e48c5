"""Joint friction and rotor inertia: per joint, linear in their values.

    Coulomb:   Fc * sign(qd)                      [Nm]
    viscous:   Fv * qd                            [Nm s/rad]
    Stribeck:  Fs * sign(qd) * exp(-(qd/vs)^2)    [Nm] at a fixed vs (variants; vs refined once selected)
    armature:  Ia * qdd                           [kg m^2] (reflected rotor inertia)

sign(qd) is smoothed (Context.sign) so that standstill noise does not flip it.
(Units for a prismatic joint: N, N s/m, kg.)
"""

from __future__ import annotations

import numpy as np

from .base import Effect


class _Dissipative(Effect):
    """Friction opposes motion and a rotor inertia is positive: only positive values qualify."""

    def plausible(self, values):
        return bool(np.all(values > 0))


class Coulomb(_Dissipative):
    name, parameters, units = "coulomb", ("Fc",), ("Nm",)

    def columns(self, context, signals, tau_model):
        return context.sign(signals.qd)[:, :, None]


class Viscous(_Dissipative):
    name, parameters, units = "viscous", ("Fv",), ("Nm s/rad",)

    def columns(self, context, signals, tau_model):
        return signals.qd[:, :, None]


class Stribeck(_Dissipative):
    name, parameters, units = "stribeck", ("Fs",), ("Nm",)
    refinable = True

    def __init__(self, velocity: float):
        self.velocity = float(velocity)
        self.label = f"vs={self.velocity:g}"

    def fixed(self):
        return {"vs": self.velocity}

    @property
    def setting(self):
        return self.velocity

    def search_interval(self, values):
        return self.velocity / 3, self.velocity * 3  # reaches the neighbouring variants

    def at(self, setting):
        return Stribeck(setting)

    def columns(self, context, signals, tau_model):
        qd = signals.qd
        return (context.sign(qd) * np.exp(-(qd / self.velocity) ** 2))[:, :, None]


class Armature(_Dissipative):
    name, parameters, units = "armature", ("Ia",), ("kg m^2",)

    def columns(self, context, signals, tau_model):
        return signals.qdd[:, :, None]
