"""Joint friction and rotor inertia as candidates of the diagnosis: per joint, linear in their
values (the laws, their ranges and columns: terms/friction.py).

Variants: Coulomb at a few velocity scales vc and Stribeck at a few velocities vs, refined once
selected (refine.py); the ripple's positions clipped to the fit data's (Context.q_range).

The Coulomb velocity scale vc is fitted because real joints do not switch sharply: in stick
phases and reversals friction takes any value in [-Fc, Fc], which a smooth law with a wider
vc follows better than a sharp sign. sign(qd) elsewhere is smoothed (Context.sign) so that
standstill noise does not flip it. (Units for a prismatic joint: N, N s/m, kg.)
"""

from __future__ import annotations

import numpy as np

from ... import terms
from .base import Effect

# A Stribeck velocity below this many Coulomb velocity scales only reshapes the Coulomb law:
# tanh(3) = 0.995, so beyond it the Coulomb law has switched before static friction decays.
STRIBECK_WIDER = 3.0
STATIC_EXCESS = 3.0  # Stribeck's static friction above the Coulomb level at most this times that level
STATIC_RESOLVED = 0.25  # ... and at least this share of it (see Stribeck.refusal_beside)
RIPPLE_SEPARABLE = 4.0  # harmonics' amplitudes summing to more than this many peaks of their torque: not separable


class _Dissipative(Effect):
    """Friction opposes motion and a rotor inertia is positive: only positive values qualify
    (the term's range)."""

    local = True


class Coulomb(_Dissipative):
    term = terms.Coulomb
    refinable = True
    simulator = ("friction", "Fc")

    def __init__(self, velocity: float):
        self.velocity = float(velocity)
        self.label = f"vc={self.velocity:g}"

    def fixed(self):
        return {"vc": self.velocity}

    @property
    def setting(self):
        return self.velocity

    def search_interval(self, values, beside=()):
        # Reaches the neighbouring variants; below a Stribeck velocity on the joint (static
        # friction breaks away within the Coulomb transition and decays after it; a Coulomb scale
        # refined freely drifts up to the Stribeck velocity until the two laws merge).
        hi = min([self.velocity * 4] + [e.velocity / STRIBECK_WIDER for e in beside if isinstance(e, Stribeck)])
        return min(self.velocity / 4, hi), hi

    def at(self, setting):
        return Coulomb(setting)

    @classmethod
    def friction_terms(cls, values, variant):
        return {"Fc": values["Fc"], "vc": variant["vc"]}  # the fitted velocity scale

    def columns(self, context, signals, tau_model):
        return self.term.columns(signals.qd, self.velocity)


class Direction(Effect):
    term = terms.Direction
    secondary = local = True

    @classmethod
    def friction_terms(cls, values, variant):
        return {"dFc": values["dFc"]}  # its sign's smoothing: the context's (friction_vector)

    def columns(self, context, signals, tau_model):
        return self.term.columns(signals.qd, context.sign_velocity)


class Ripple(Effect):
    term = terms.Ripple
    HARMONICS = terms.Ripple.HARMONICS
    ranged = True

    def columns(self, context, signals, tau_model):
        return self.term.columns(signals.q, [joint.revolute for joint in context.robot.joints], context.q_range)

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


class Viscous(_Dissipative):
    term = terms.Viscous
    simple_term = "Fv"
    simulator = ("damping", "Fv")

    @classmethod
    def friction_terms(cls, values, variant):
        return {"Fv": values["Fv"]}

    def columns(self, context, signals, tau_model):
        return self.term.columns(signals.qd)


class Stribeck(_Dissipative):
    term = terms.Stribeck
    refinable = True
    # Static friction above the Coulomb level. Alone, it would be friction that vanishes at
    # speed, which no joint has, and the viscous law would then take the Coulomb level's place
    # (extrapolating steeply beyond the fit speeds).
    extends = "coulomb"

    def __init__(self, velocity: float):
        self.velocity = float(velocity)
        self.label = f"vs={self.velocity:g}"

    def fixed(self):
        return {"vs": self.velocity}

    @property
    def setting(self):
        return self.velocity

    def search_interval(self, values, beside=()):
        # Reaches the neighbouring variants; no narrower than STRIBECK_WIDER times the joint's
        # Coulomb scale (see reshapes).
        lo = max([self.velocity / 3] + [STRIBECK_WIDER * e.velocity for e in beside if isinstance(e, Coulomb)])
        return lo, max(self.velocity * 3, lo)

    def at(self, setting):
        return Stribeck(setting)

    def refusal_beside(self, values, base):
        """Static friction above the Coulomb level, between STATIC_RESOLVED and STATIC_EXCESS
        times that level. A breakaway torque of ten Coulomb levels at a reversal is no joint's:
        it is a spike standing in for a conditioning artefact (at 100 Hz, 17-bit positions: Fs
        10.5 Nm beside Fc 1.0). A small excess is what a low-pass filter makes of the reversals
        of friction that sticks, where the torque takes any value within the Coulomb levels
        while the filtered velocity passes through zero smoothly (withheld benchmark, `sticky`,
        no static friction injected: 0.04-0.13 Nm beside 0.4-0.9 Nm; injected static friction
        came out at 0.9-1.6 Coulomb levels)."""
        if np.any(values > STATIC_EXCESS * base):
            return f"static friction above {STATIC_EXCESS:g} Coulomb levels is no joint's"
        if np.any(values < STATIC_RESOLVED * base):
            return (f"static friction less than {STATIC_RESOLVED:g} of the Coulomb level above it is not told apart "
                    "from a filter's rounding of reversals where friction sticks")
        return ""

    def reshapes(self, other):
        """No wider than STRIBECK_WIDER times the joint's Coulomb velocity scale (up to the
        search's 1 % tolerance: refined onto that bound): there the two laws trade shape with
        each other, and no static friction is shown."""
        return isinstance(other, Coulomb) and self.velocity < 1.02 * STRIBECK_WIDER * other.velocity

    @classmethod
    def friction_terms(cls, values, variant):
        return {"Fs": values["Fs"], "vs": variant["vs"]}  # its sign's smoothing: the context's (friction_vector)

    def columns(self, context, signals, tau_model):
        return self.term.columns(signals.qd, self.velocity, context.sign_velocity)


class Armature(_Dissipative):
    term = terms.Armature
    simulator = ("armature", "Ia")

    def columns(self, context, signals, tau_model):
        return self.term.columns(signals.qdd)
