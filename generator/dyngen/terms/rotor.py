"""The drive train's terms, per joint and of its own motion (columns (T, N, k)):

    ripple     sum_k a_k cos(k q) + b_k sin(k q)    [Nm]        gear and cogging harmonics of the joint's position
    armature   Ia qdd                               [kg m^2]    reflected rotor inertia (kg for a prismatic joint)"""

from __future__ import annotations

import numpy as np

from .term import Term, Value
from .friction import POSITIVE

RIPPLE_SEPARABLE = 4.0  # harmonics' amplitudes summing to more than this many peaks of their torque: not separable


class Ripple(Term):
    """Known only where the data went: q is clipped to the fit data's range; a prismatic joint has none."""

    HARMONICS = (1, 2, 3)
    name, doc = "ripple", "position ripple sum_k a_k cos(k q) + b_k sin(k q) (gear and cogging harmonics)"
    values = tuple(Value(f"{ab}{k}", "Nm") for k in HARMONICS for ab in ("a", "b"))
    ranged = True

    @staticmethod
    def harmonic(q, k: int, kind: str):
        return (np.cos if kind == "cos" else np.sin)(k * q)  # 1 * q is q, bit for bit

    @classmethod
    def regressor(cls, q, revolute, q_range=None, harmonics=HARMONICS):
        if q_range is not None:
            q = np.clip(q, *q_range)
        out = np.stack([f(k * q) for k in harmonics for f in (np.cos, np.sin)], axis=-1)
        out[..., ~np.asarray(revolute, dtype=bool), :] = 0.0
        return out

    def columns(self, context, signals, tau_model):
        return self.regressor(signals.q, [joint.revolute for joint in context.robot.joints], context.q_range)

    def derived(self, robot, values, std, torque_rms):
        if None in values.values():
            return {}
        amplitudes = [float(np.hypot(values[f"a{k}"], values[f"b{k}"])) for k in self.HARMONICS]
        # Low harmonics over a short range of positions are nearly collinear: large values of
        # opposite sign whose sum is small. Then only the sum is a finding.
        rms = torque_rms()
        return {"amplitude_Nm": amplitudes, "torque_rms_Nm": rms,
                "separable": bool(sum(amplitudes) <= RIPPLE_SEPARABLE * np.sqrt(2) * rms)}

    @classmethod
    def warnings(cls, finding):
        d = finding.derived
        if d.get("separable", True):
            return []
        return [f"ripple on joint {finding.joints[0]}: its harmonics are not separable over the positions the fit "
                f"data cover (amplitudes {', '.join(f'{a:.3g}' for a in d['amplitude_Nm'])} Nm for "
                f"a torque of {d['torque_rms_Nm']:.3g} Nm RMS): only their sum is a finding"]


class Armature(Term):
    name, doc = "armature", "rotor inertia Ia qdd (reflected through the gear)"
    values = (Value("Ia", "kg m^2", **POSITIVE),)
    local, simulator = True, ("armature", "Ia")

    @staticmethod
    def regressor(qdd):
        return qdd[..., None]

    def columns(self, context, signals, tau_model):
        return self.regressor(signals.qdd)
