"""The rigid body: the base regressor Y(q, qd, qdd) of the full dynamics, and a payload on the
last link (the Newton-Euler torques of its 10 standard parameters, m, mx, my, mz, XX, XY, XZ,
YY, YZ, ZZ in the last link's frame, docs/conventions.md)."""

from __future__ import annotations

import numpy as np

from ..parameters import PER_LINK, STANDARD_NAMES_PER_LINK
from .base import Term, Value


class RigidBody(Term):
    name, scope, doc = "rigid_body", "arm", "the rigid body's base coefficients: Y(q, qd, qdd) pi"

    @staticmethod
    def columns(model, q, qd, qdd):
        """(T, N, r): the compiled model's base regressor."""
        return model.batch("regressor", q, qd, qdd)


class Payload(Term):
    """A body has a positive mass, not more than the arm's, and its centre of mass within a metre
    of the flange frame."""

    name, scope, doc = "payload", "arm", "a payload: a body fixed to the last link (its 10 standard parameters)"
    values = tuple(Value(n, u) for n, u in zip(STANDARD_NAMES_PER_LINK, (
        "kg", "kg m", "kg m", "kg m", "kg m^2", "kg m^2", "kg m^2", "kg m^2", "kg m^2", "kg m^2")))
    REACH = 1.0  # m: the centre of mass at most this far from the flange frame

    @classmethod
    def inside(cls, values, scales=None):
        m = values[0]
        return bool(0 < m < scales["arm mass"] and np.linalg.norm(values[1:4]) < cls.REACH * m)

    @staticmethod
    def columns(model, q, qd, qdd, units) -> np.ndarray:
        """(T, N, k): Newton-Euler torques of the last link's standard parameters units[k]."""
        n = q.shape[1]
        out = np.empty(q.shape + (len(units),))
        for k, unit in enumerate(units):
            s = np.zeros(PER_LINK * n)
            s[PER_LINK * (n - 1):] = unit
            out[:, :, k] = model.batch("rnea", q, qd, qdd, s)
        return out


def armature_identifiable(model, dof: int, seed: int = 0) -> list[bool]:
    """Per joint, whether its rotor inertia Ia_j qdd_j (terms.Armature) is independent of the rigid
    body's base columns (at random states of the compiled model)."""
    rng = np.random.default_rng(seed)
    states = 40
    q, qd, qdd = (rng.uniform(-2, 2, (states, dof)) for _ in range(3))
    Y = model.batch("regressor", q, qd, qdd).reshape(states * dof, -1)
    ok = []
    for j in range(dof):
        col = np.zeros((states, dof))
        col[:, j] = qdd[:, j]
        col = col.reshape(-1)
        x, *_ = np.linalg.lstsq(Y, col, rcond=None)
        ok.append(bool(np.linalg.norm(Y @ x - col) > 1e-8 * np.linalg.norm(col)))
    return ok
