"""What every torque term states: its values, their physical range, its columns and its law.

A term is a torque linear in its fitted values: tau_term = columns @ values. Its nonlinear
settings (a velocity scale, a lag) are fixed while it is fitted. Columns are computed from
samples (q, qd, qdd, t, the model's torque) with numpy; a `pointwise` term's columns of a
chunk of samples need that chunk alone, so the normal equations A^T A, A^T b of any fit that
uses it accumulate chunk by chunk (a time shift needs the samples up to its lag before; a
`switching` term's columns go through the recording's low-pass like the torque, which needs
the filter's overlap at a chunk's ends).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Value:
    """A fitted value or a setting: its name, unit, and the open interval (low, high) a
    physical one lies in (units of `per`: "" absolute, "g" the size of gravity, "arm mass")."""

    name: str
    unit: str
    low: float = -np.inf
    high: float = np.inf
    per: str = ""

    def inside(self, x: float, scales: dict | None = None) -> bool:
        s = 1.0 if not self.per else float((scales or {})[self.per])
        return bool((self.low == -np.inf or x > self.low * s) and (self.high == np.inf or x < self.high * s))


@dataclass(frozen=True)
class FrictionField:
    """One entry of a joint's friction vector (the generated <robot>_friction's f): a term's value
    (kind "value") or setting (kind "velocity": a scale, the plain sign or no term when <= 0)."""

    name: str
    kind: str  # "value" | "velocity"
    doc: str


class Term:
    """name: the term's identifier; scope "joint" (one candidate per joint, acting on it) or
    "arm"; values: its fitted values; settings: its nonlinear settings; doc: one line (the law).
    `friction`: its entries of the emitted friction vector and `c`, its C on one joint."""

    name = ""
    scope = "joint"
    doc = ""
    values: tuple = ()
    settings: tuple = ()
    pointwise = True
    switching = False  # switches with the sign of the velocity: filtered like the torque it explains
    friction: tuple = ()  # FrictionField, in the order of the vector

    @classmethod
    def parameters(cls) -> tuple:
        return tuple(v.name for v in cls.values)

    @classmethod
    def units(cls) -> tuple:
        return tuple(v.unit for v in cls.values)

    @classmethod
    def inside(cls, values, scales: dict | None = None) -> bool:
        """Whether fitted values are physical: each inside its range (terms whose values are
        bounded together say so here)."""
        values = np.atleast_1d(values)
        return all(v.inside(x, scales) for v, x in zip(cls.values, values))

    @classmethod
    def c(cls, v: str, f, c) -> str:
        """C expression of the term's torque on one joint: v the velocity, f(name) its fields, c
        the C names of sgn(v, e) (base.sign), exp, abs (|x|) and zero (attributes)."""
        raise NotImplementedError

    @classmethod
    def torque(cls, m, v, f: dict):
        """Its torque at velocity v for fields f, with math module m (numpy or mpmath): the same
        law as `c`, the oracle the emitted C is checked against."""
        raise NotImplementedError


def sign(m, v, scale):
    """sign(v) smoothed as tanh(v / scale); the plain sign when scale <= 0 (the C's sgn)."""
    if scale > 0:
        return m.tanh(v / scale)
    return m.sign(v)
