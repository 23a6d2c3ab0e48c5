"""Joint friction, per joint, of its own motion (columns (T, N, k)):

    coulomb    Fc tanh(qd / vc)                     [Nm]        vc: the law's velocity scale
    viscous    Fv qd                                [Nm s/rad]
    stribeck   Fs tanh(qd / es) exp(-(qd / vs)^2)   [Nm]        static friction above the Coulomb level
    direction  dFc |tanh(qd / ed)|                  [Nm]        Coulomb levels Fc + dFc forwards, Fc - dFc backwards

Each velocity scale is its own term's, carried in the emitted vector: the firmware's friction is
the law that was measured. vc is fitted (real joints do not switch sharply); es and ed are the
diagnosis's sign velocity (Context.sign_velocity), so that standstill noise does not flip them."""

from __future__ import annotations

import numpy as np

from .term import FrictionField, Term, Value, sign

# The Coulomb law's velocity scale vc, by its use (one place for every default):
SIMPLE_SCALE = 0.02  # rad/s: the simple model's fixed scale, and identify's when not searched
SCALE_VARIANTS = (0.002, 0.01, 0.05)  # the diagnosis's variants (refined once selected)
SCALE_GRID = (1e-5, 1e-4, 0.0005, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1)  # identify's per-joint search
EXCITATION_SCALE = 0.01  # the excitation's information matrix (a sharper law excites no differently)
SIGN_SCALE = 0.002  # the Stribeck and direction terms' sign smoothing (diagnose --sign-velocity)
STRIBECK_VARIANTS = (0.03, 0.1, 0.3)  # rad/s: the diagnosis's Stribeck velocities (well above SIGN_SCALE)
POSITIVE = dict(low=0.0)  # friction opposes motion (a rotor inertia is positive)
# A Stribeck velocity below this many Coulomb velocity scales only reshapes the Coulomb law:
# tanh(3) = 0.995, so beyond it the Coulomb law has switched before static friction decays.
STRIBECK_WIDER = 3.0
STATIC_EXCESS = 3.0  # Stribeck's static friction above the Coulomb level at most this times that level
STATIC_RESOLVED = 0.25  # ... and at least this share of it (see Stribeck.refusal_beside)


def coulomb(qd, vc):
    return np.tanh(qd / vc)


class _AtVelocity(Term):
    """A friction term at one velocity setting (its field `field`), refined once selected."""

    field = ""
    switching = refinable = local = True

    def __init__(self, velocity: float):
        self.velocity = float(velocity)
        self.label = f"{self.field}={self.velocity:g}"

    def fixed(self):
        return {self.field: self.velocity}

    @property
    def setting(self):
        return self.velocity

    def at(self, setting):
        return type(self)(setting)


class Coulomb(_AtVelocity):
    name, doc = "coulomb", "Coulomb friction Fc tanh(qd / vc), vc fitted (real joints do not switch sharply)"
    field = "vc"
    values = (Value("Fc", "Nm", **POSITIVE),)
    settings = (Value("vc", "rad/s", **POSITIVE),)
    friction = (FrictionField("Fc", "value", "Coulomb friction [Nm or N]"),
                FrictionField("vc", "velocity", "its velocity scale: tanh(qd / vc); the plain sign when <= 0 [rad/s or m/s]"))
    simulator = ("friction", "Fc")

    @staticmethod
    def regressor(qd, vc):
        return coulomb(qd, vc)[..., None]

    @classmethod
    def c(cls, v, f, c):
        return f"{f('Fc')} * {c.sgn}({v}, {f('vc')})"

    @classmethod
    def torque(cls, m, v, f):
        return f["Fc"] * sign(m, v, f["vc"])

    def columns(self, context, signals, tau_model):
        return self.regressor(signals.qd, self.velocity)

    def search_interval(self, values, beside=()):
        # Reaches the neighbouring variants; below a Stribeck velocity on the joint (static
        # friction breaks away within the Coulomb transition and decays after it; a Coulomb scale
        # refined freely drifts up to the Stribeck velocity until the two laws merge).
        hi = min([self.velocity * 4] + [e.velocity / STRIBECK_WIDER for e in beside if isinstance(e, Stribeck)])
        return min(self.velocity / 4, hi), hi


class Viscous(Term):
    name, doc = "viscous", "viscous friction Fv qd"
    values = (Value("Fv", "Nm s/rad", **POSITIVE),)
    friction = (FrictionField("Fv", "value", "viscous friction [Nm s/rad or N s/m]"),)
    local, simple_term, simulator = True, "Fv", ("damping", "Fv")

    @staticmethod
    def regressor(qd):
        return qd[..., None]

    @classmethod
    def c(cls, v, f, c):
        return f"{f('Fv')} * {v}"

    @classmethod
    def torque(cls, m, v, f):
        return f["Fv"] * v

    def columns(self, context, signals, tau_model):
        return self.regressor(signals.qd)


class Stribeck(_AtVelocity):
    name, doc = "stribeck", "Stribeck friction Fs tanh(qd / es) exp(-(qd / vs)^2): breakaway friction above Coulomb's"
    field = "vs"
    values = (Value("Fs", "Nm", **POSITIVE),)
    settings = (Value("vs", "rad/s", **POSITIVE), Value("es", "rad/s", **POSITIVE))
    friction = (FrictionField("Fs", "value", "Stribeck friction (breakaway minus Coulomb) [Nm or N]"),
                FrictionField("vs", "velocity", "Stribeck velocity; no Stribeck term when <= 0 [rad/s or m/s]"),
                FrictionField("es", "velocity", "its sign's smoothing: tanh(qd / es); the plain sign when <= 0 "
                                                "[rad/s or m/s]"))
    # Static friction above the Coulomb level. Alone, it would be friction that vanishes at
    # speed, which no joint has, and the viscous law would then take the Coulomb level's place
    # (extrapolating steeply beyond the fit speeds).
    extends = "coulomb"

    @staticmethod
    def regressor(qd, vs, es):
        return (np.tanh(qd / es) * np.exp(-(qd / vs) ** 2))[..., None]

    @classmethod
    def c(cls, v, f, c):
        r = f"({v} / {f('vs')})"
        return f"({f('vs')} > {c.zero} ? {f('Fs')} * {c.sgn}({v}, {f('es')}) * {c.exp}(-{r} * {r}) : {c.zero})"

    @classmethod
    def torque(cls, m, v, f):
        return f["Fs"] * sign(m, v, f["es"]) * m.exp(-(v / f["vs"]) ** 2) if f["vs"] > 0 else 0 * v

    def columns(self, context, signals, tau_model):
        return self.regressor(signals.qd, self.velocity, context.sign_velocity)

    def search_interval(self, values, beside=()):
        # Reaches the neighbouring variants; no narrower than STRIBECK_WIDER times the joint's
        # Coulomb scale (see reshapes).
        lo = max([self.velocity / 3] + [STRIBECK_WIDER * e.velocity for e in beside if isinstance(e, Coulomb)])
        return lo, max(self.velocity * 3, lo)

    def refusal_beside(self, values, base):
        """Static friction between STATIC_RESOLVED and STATIC_EXCESS Coulomb levels: ten levels at a reversal
        is a conditioning artefact (100 Hz, 17-bit positions: Fs 10.5 Nm beside Fc 1.0); a small excess is
        a filter's rounding of reversals where friction sticks (docs/measured-data.md, `sticky`)."""
        if np.any(values > STATIC_EXCESS * base):
            return f"static friction above {STATIC_EXCESS:g} Coulomb levels is no joint's"
        if np.any(values < STATIC_RESOLVED * base):
            return (f"static friction less than {STATIC_RESOLVED:g} of the Coulomb level above it is not told apart "
                    "from a filter's rounding of reversals where friction sticks")
        return ""

    def reshapes(self, other):
        """No wider than STRIBECK_WIDER Coulomb scales (up to the search's 1 %): the two laws trade shape."""
        return isinstance(other, Coulomb) and self.velocity < 1.02 * STRIBECK_WIDER * other.velocity


class Direction(Term):
    name, doc = "direction", "direction-dependent Coulomb friction dFc |tanh(qd / ed)| (Fc + dFc forwards, Fc - dFc back)"
    switching = secondary = local = True
    values = (Value("dFc", "Nm"),)
    settings = (Value("ed", "rad/s", **POSITIVE),)
    friction = (FrictionField("dFc", "value", "Coulomb level's excess moving forwards over moving backwards, halved "
                                              "[Nm or N]"),
                FrictionField("ed", "velocity", "its sign's smoothing: |tanh(qd / ed)|; |sign| when <= 0 [rad/s or m/s]"))

    @staticmethod
    def regressor(qd, ed):
        return np.abs(np.tanh(qd / ed))[..., None]

    @classmethod
    def c(cls, v, f, c):
        return f"{f('dFc')} * {c.sgn}({c.abs}({v}), {f('ed')})"  # |tanh(v / ed)| = tanh(|v| / ed)

    @classmethod
    def torque(cls, m, v, f):
        return f["dFc"] * abs(sign(m, v, f["ed"]))

    def columns(self, context, signals, tau_model):
        return self.regressor(signals.qd, context.sign_velocity)


IN_FRICTION = (Coulomb, Viscous, Stribeck, Direction)  # the terms of the emitted friction routine, in its order
FRICTION_FIELDS = tuple(field for term in IN_FRICTION for field in term.friction)
FRICTION_NAMES = tuple(field.name for field in FRICTION_FIELDS)


def friction_torque(m, qd, f) -> list:
    """Per joint, the emitted routine's friction at velocities qd for the vector f, with math module m."""
    n = len(FRICTION_NAMES)
    joints = [dict(zip(FRICTION_NAMES, f[n * j: n * (j + 1)])) for j in range(len(qd))]  # each joint's fields
    return [sum(term.torque(m, v, fields) for term in IN_FRICTION) for v, fields in zip(qd, joints)]


def c_terms(names, v: str = "v", vector: str = "fj") -> list[dict]:
    """The friction template's terms: doc, fields and C on one joint (v, vector[k]; names: sgn, exp, abs, zero)."""
    index = {name: k for k, name in enumerate(FRICTION_NAMES)}
    return [{"name": term.name, "doc": term.doc, "fields": term.friction,
             "c": term.c(v, lambda name: f"{vector}[{index[name]}]", names)} for term in IN_FRICTION]
