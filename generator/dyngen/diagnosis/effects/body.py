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

    def columns(self, context, signals, tau_model):
        n = signals.q.shape[1]
        out = np.empty(signals.q.shape + (PER_LINK,))
        for k in range(PER_LINK):
            unit = np.zeros(PER_LINK * n)
            unit[PER_LINK * (n - 1) + k] = 1.0
            out[:, :, k] = context.model.batch(RNEA.name, signals.q, signals.qd, signals.qdd, unit)
        return out


class Coefficients(Effect):
    name, scope = "coefficients", "arm"

    def __init__(self):
        self.parameters, self.units = (), ()

    def bind(self, manifest) -> "Coefficients":
        self.parameters = tuple(e["standard"] for e in manifest["coefficients"]["full"]["expressions"])
        self.units = ("SI",) * len(self.parameters)
        return self

    def columns(self, context, signals, tau_model):
        if not self.parameters:
            self.bind(context.model.manifest)
        return context.model.batch(REGRESSOR.name, signals.q, signals.qd, signals.qdd)
