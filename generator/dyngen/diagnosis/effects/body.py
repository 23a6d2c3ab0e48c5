"""Errors in the rigid-body model: a payload on the last link, or the model's coefficients.

payload: the 10 standard parameters (m, mx, my, mz, XX, XY, XZ, YY, YZ, ZZ, frame of the
  last link, docs/conventions.md) of a body fixed to the last link. Newton-Euler is linear in
  the standard parameters, so its torque columns are rnea(q, qd, qdd, e_k) with e_k the unit
  vector of the last link's k-th parameter.
coefficients: errors in every base coefficient of the full dynamics, columns Y(q, qd, qdd).
"""

from __future__ import annotations

import numpy as np

from ...catalogue import REGRESSOR, RNEA
from ...parameters import PER_LINK, STANDARD_NAMES_PER_LINK
from .base import Effect


class Payload(Effect):
    name, scope = "payload", "arm"
    parameters = STANDARD_NAMES_PER_LINK
    units = ("kg", "kg m", "kg m", "kg m", "kg m^2", "kg m^2", "kg m^2", "kg m^2", "kg m^2", "kg m^2")

    def __init__(self, max_mass: float):
        self.max_mass = float(max_mass)  # kg: the arm's own mass; a heavier "payload" is refused

    @classmethod
    def of(cls, context):
        return cls(float(np.sum(np.asarray(context.p, dtype=float).reshape(-1, PER_LINK)[:, 0])))

    def plausible(self, values):
        """A body has a positive mass, not more than the arm's, and its centre of mass
        within a metre of the flange frame."""
        m = values[0]
        return bool(0 < m < self.max_mass and np.linalg.norm(values[1:4]) < 1.0 * m)

    def simplified(self, values):
        """A fitted inertia that is no body's (a negative principal moment about its centre of
        mass): a point mass at the fitted centre instead. The data determine m and m c, not that
        inertia, and an impossible inertia mispredicts other motions."""
        if consistent_inertia(values):
            return None
        refusal = {"candidate": "the payload's inertia about its centre of mass (a negative principal moment; "
                                "the payload is kept as a point mass at its fitted centre)",
                   "values": values[4:].tolist()}
        return PointPayload(values[1:4] / values[0], self.max_mass), refusal

    def columns(self, context, signals, tau_model):
        n = signals.q.shape[1]
        out = np.empty(signals.q.shape + (PER_LINK,))
        for k in range(PER_LINK):
            unit = np.zeros(PER_LINK * n)
            unit[PER_LINK * (n - 1) + k] = 1.0
            out[:, :, k] = context.model.batch(RNEA.name, signals.q, signals.qd, signals.qdd, unit)
        return out

    def derived(self, robot, values, std, torque_rms):
        m = values.get("m")
        if m in (None, 0.0):
            return {}
        return {"mass_kg": m,
                "com_m": [values[k] / m if values.get(k) is not None else None for k in ("mx", "my", "mz")]}

    @classmethod
    def last_link(cls, values):
        return None if None in values.values() else standard_of_payload(values)


class PointPayload(Payload):
    """A payload as a point mass at c0 (the centre of mass of a fitted Payload whose inertia
    about its centre came out physically impossible: the data do not determine it). Values m
    and m c; the inertia about the frame origin is m (|c0|^2 1 - c0 c0^T), always consistent."""

    parameters = ("m", "mx", "my", "mz")
    units = ("kg", "kg m", "kg m", "kg m")

    def __init__(self, centre, max_mass: float):
        super().__init__(max_mass)
        self.centre = np.asarray(centre, dtype=float)
        self.label = "point mass at c0=(" + ",".join(f"{x:.4g}" for x in self.centre) + ")"

    def fixed(self):
        return {"point_mass_at": [float(x) for x in self.centre]}

    def simplified(self, values):
        return None  # a point mass is always a body

    def columns(self, context, signals, tau_model):
        n = signals.q.shape[1]
        c = self.centre
        I = c @ c * np.eye(3) - np.outer(c, c)  # unit mass
        units = [np.array([1.0, 0, 0, 0, I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]]),
                 *np.eye(PER_LINK)[1:4]]
        out = np.empty(signals.q.shape + (4,))
        for k, unit in enumerate(units):
            s = np.zeros(PER_LINK * n)
            s[PER_LINK * (n - 1):] = unit
            out[:, :, k] = context.model.batch(RNEA.name, signals.q, signals.qd, signals.qdd, s)
        return out


def consistent_inertia(values, tolerance: float = 0.0) -> bool:
    """Whether a fitted payload's 10 standard values (m, m c, inertia about the frame origin)
    describe a body: inertia about its centre of mass with non-negative principal moments that
    satisfy the triangle inequalities."""
    m, mc = values[0], np.asarray(values[1:4])
    XX, XY, XZ, YY, YZ, ZZ = values[4:10]
    c = mc / m
    Ic = np.array([[XX, XY, XZ], [XY, YY, YZ], [XZ, YZ, ZZ]]) - m * (c @ c * np.eye(3) - np.outer(c, c))
    e = np.linalg.eigvalsh(Ic)
    return bool(e[0] >= -tolerance and e[0] + e[1] >= e[2] - tolerance)


def standard_of_payload(values: dict) -> np.ndarray:
    """The 10 standard parameters of a selected payload (10 values, or a point mass's 4)."""
    v = [values[k] for k in ("m", "mx", "my", "mz")]
    if "XX" in values:
        return np.array(list(values.values()), dtype=float)
    m, c = v[0], np.array(v[1:4]) / v[0]
    I = m * (c @ c * np.eye(3) - np.outer(c, c))
    return np.array([m, *v[1:4], I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]])


class Coefficients(Effect):
    name, scope = "coefficients", "arm"

    def __init__(self, parameters):
        self.parameters = tuple(parameters)  # the standard names of the full model's base coefficients
        self.units = ("SI",) * len(self.parameters)

    @classmethod
    def of(cls, context):
        return cls(e["standard"] for e in context.model.manifest["coefficients"]["full"]["expressions"])

    def columns(self, context, signals, tau_model):
        return context.model.batch(REGRESSOR.name, signals.q, signals.qd, signals.qdd)
