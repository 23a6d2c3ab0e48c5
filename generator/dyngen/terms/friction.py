"""Joint friction and rotor inertia: per joint, each acting on its own joint
and depending on its own motion alone (columns (T, N, k): entry [:, j] acts on joint j).

    coulomb    Fc tanh(qd / vc)                     [Nm]        vc: the law's velocity scale
    viscous    Fv qd                                [Nm s/rad]
    stribeck   Fs tanh(qd / es) exp(-(qd / vs)^2)   [Nm]        static friction above the Coulomb level
    direction  dFc |tanh(qd / ed)|                  [Nm]        Coulomb levels Fc + dFc forwards, Fc - dFc backwards
    ripple     sum_k a_k cos(k q) + b_k sin(k q)    [Nm]        gear and cogging harmonics of the joint's position
    armature   Ia qdd                               [kg m^2]    reflected rotor inertia

Every velocity scale belongs to its own term (vc, es, ed are three numbers, each the one its
term was fitted with): the emitted friction vector carries each (FRICTION_FIELDS), so the
firmware's friction is the law that was measured. (Units for a prismatic joint: N, N s/m, kg.)
"""

from __future__ import annotations

import numpy as np

from .base import FrictionField, Term, Value, sign

# The Coulomb law's velocity scale vc, by its use (one place for every default):
SIMPLE_SCALE = 0.02  # rad/s: the simple model's fixed scale, and identify's when not searched
SCALE_VARIANTS = (0.002, 0.01, 0.05)  # the diagnosis's variants (refined once selected)
SCALE_GRID = (1e-5, 1e-4, 0.0005, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1)  # identify's per-joint search
EXCITATION_SCALE = 0.01  # the excitation's information matrix (a sharper law excites no differently)
SIGN_SCALE = 0.002  # the Stribeck and direction terms' sign smoothing (diagnose --sign-velocity)
STRIBECK_VARIANTS = (0.03, 0.1, 0.3)  # rad/s: the diagnosis's Stribeck velocities (well above SIGN_SCALE)
POSITIVE = dict(low=0.0)  # friction opposes motion, a rotor inertia is positive


def coulomb(qd, vc):
    """tanh(qd / vc): the Coulomb law's shape (any array, vc broadcast)."""
    return np.tanh(qd / vc)


def stribeck(qd, vs, es):
    """tanh(qd / es) exp(-(qd / vs)^2): static friction decaying with speed."""
    return np.tanh(qd / es) * np.exp(-(qd / vs) ** 2)


def direction(qd, ed):
    """|tanh(qd / ed)|: the same sign of torque both ways."""
    return np.abs(np.tanh(qd / ed))


class Coulomb(Term):
    name, doc = "coulomb", "Coulomb friction Fc tanh(qd / vc), vc fitted (real joints do not switch sharply)"
    switching = True
    values = (Value("Fc", "Nm", **POSITIVE),)
    settings = (Value("vc", "rad/s", **POSITIVE),)
    friction = (FrictionField("Fc", "value", "Coulomb friction [Nm or N]"),
                FrictionField("vc", "velocity", "its velocity scale: tanh(qd / vc); the plain sign when <= 0 [rad/s or m/s]"))

    @staticmethod
    def columns(qd, vc):
        return coulomb(qd, vc)[..., None]

    @classmethod
    def c(cls, v, f, c):
        return f"{f('Fc')} * {c.sgn}({v}, {f('vc')})"

    @classmethod
    def torque(cls, m, v, f):
        return f["Fc"] * sign(m, v, f["vc"])


class Viscous(Term):
    name, doc = "viscous", "viscous friction Fv qd"
    values = (Value("Fv", "Nm s/rad", **POSITIVE),)
    friction = (FrictionField("Fv", "value", "viscous friction [Nm s/rad or N s/m]"),)

    @staticmethod
    def columns(qd):
        return qd[..., None]

    @classmethod
    def c(cls, v, f, c):
        return f"{f('Fv')} * {v}"

    @classmethod
    def torque(cls, m, v, f):
        return f["Fv"] * v


class Stribeck(Term):
    name, doc = "stribeck", "Stribeck friction Fs tanh(qd / es) exp(-(qd / vs)^2): breakaway friction above Coulomb's"
    switching = True
    values = (Value("Fs", "Nm", **POSITIVE),)
    settings = (Value("vs", "rad/s", **POSITIVE), Value("es", "rad/s", **POSITIVE))
    friction = (FrictionField("Fs", "value", "Stribeck friction (breakaway minus Coulomb) [Nm or N]"),
                FrictionField("vs", "velocity", "Stribeck velocity; no Stribeck term when <= 0 [rad/s or m/s]"),
                FrictionField("es", "velocity", "its sign's smoothing: tanh(qd / es); the plain sign when <= 0 "
                                                "[rad/s or m/s]"))

    @staticmethod
    def columns(qd, vs, es):
        return stribeck(qd, vs, es)[..., None]

    @classmethod
    def c(cls, v, f, c):
        r = f"({v} / {f('vs')})"
        return f"({f('vs')} > {c.zero} ? {f('Fs')} * {c.sgn}({v}, {f('es')}) * {c.exp}(-{r} * {r}) : {c.zero})"

    @classmethod
    def torque(cls, m, v, f):
        return f["Fs"] * sign(m, v, f["es"]) * m.exp(-(v / f["vs"]) ** 2) if f["vs"] > 0 else 0 * v


class Direction(Term):
    name, doc = "direction", "direction-dependent Coulomb friction dFc |tanh(qd / ed)| (Fc + dFc forwards, Fc - dFc back)"
    switching = True
    values = (Value("dFc", "Nm"),)
    settings = (Value("ed", "rad/s", **POSITIVE),)
    friction = (FrictionField("dFc", "value", "Coulomb level's excess moving forwards over moving backwards, halved "
                                              "[Nm or N]"),
                FrictionField("ed", "velocity", "its sign's smoothing: |tanh(qd / ed)|; |sign| when <= 0 [rad/s or m/s]"))

    @staticmethod
    def columns(qd, ed):
        return direction(qd, ed)[..., None]

    @classmethod
    def c(cls, v, f, c):
        return f"{f('dFc')} * {c.sgn}({c.abs}({v}), {f('ed')})"  # |tanh(v / ed)| = tanh(|v| / ed)

    @classmethod
    def torque(cls, m, v, f):
        return f["dFc"] * abs(sign(m, v, f["ed"]))


class Ripple(Term):
    """Known only where the data went: the diagnosis clips q to the fit data's range (harmonics
    extrapolated beyond it are guesses); a prismatic joint has none (harmonics of metres)."""

    HARMONICS = (1, 2, 3)
    name, doc = "ripple", "position ripple sum_k a_k cos(k q) + b_k sin(k q) (gear and cogging harmonics)"
    values = tuple(Value(f"{ab}{k}", "Nm") for k in HARMONICS for ab in ("a", "b"))

    @staticmethod
    def harmonic(q, k: int, kind: str):
        """cos(k q) or sin(k q) (one column, e.g. identify's first harmonic)."""
        x = q if k == 1 else k * q
        return np.cos(x) if kind == "cos" else np.sin(x)

    @classmethod
    def columns(cls, q, revolute, q_range=None, harmonics=HARMONICS):
        if q_range is not None:
            q = np.clip(q, *q_range)
        out = np.stack([f(k * q) for k in harmonics for f in (np.cos, np.sin)], axis=-1)
        out[..., ~np.asarray(revolute, dtype=bool), :] = 0.0
        return out


class Armature(Term):
    name, doc = "armature", "rotor inertia Ia qdd (reflected through the gear)"
    values = (Value("Ia", "kg m^2", **POSITIVE),)

    @staticmethod
    def columns(qdd):
        return qdd[..., None]


IN_FRICTION = (Coulomb, Viscous, Stribeck, Direction)  # the terms of the emitted friction routine, in its order
FRICTION_FIELDS = tuple(field for term in IN_FRICTION for field in term.friction)
FRICTION_NAMES = tuple(field.name for field in FRICTION_FIELDS)


def friction_torque(m, qd, f) -> list:
    """Per joint, the emitted routine's friction at velocities qd for the vector f (every
    joint's FRICTION_FIELDS in turn), with math module m: the sum of the terms' laws."""
    n = len(FRICTION_FIELDS)
    out = []
    for j, v in enumerate(qd):
        fields = dict(zip(FRICTION_NAMES, f[n * j: n * (j + 1)]))
        out.append(sum(term.torque(m, v, fields) for term in IN_FRICTION))
    return out


def c_terms(names, v: str = "v", vector: str = "fj") -> list[dict]:
    """The friction routine's terms for its template: each term's doc line, fields and C on one
    joint (v its velocity, vector[k] its k-th field; names: the C names of sgn, exp, abs and
    zero, attributes of one object)."""
    index = {name: k for k, name in enumerate(FRICTION_NAMES)}
    return [{"name": term.name, "doc": term.doc, "fields": term.friction,
             "c": term.c(v, lambda name: f"{vector}[{index[name]}]", names)} for term in IN_FRICTION]
