"""Pinocchio's controller-side algorithms on the Arm (pinocchio_arm.build): Coriolis matrix,
forward dynamics (ABA) and the analytic derivatives of inverse and forward dynamics."""
from __future__ import annotations

import numpy as np
import pinocchio as pin

from .arm import Arm
from .pinocchio_arm import build


def _v(x):
    return np.asarray(x, dtype=float)


def coriolis_matrix(arm: Arm, p, q, qd) -> np.ndarray:
    model, data = build(arm, p)
    return pin.computeCoriolisMatrix(model, data, _v(q), _v(qd)).copy()


def forward_dynamics(arm: Arm, p, q, qd, tau) -> np.ndarray:
    model, data = build(arm, p)
    return pin.aba(model, data, _v(q), _v(qd), _v(tau)).copy()


def rnea_derivatives(arm: Arm, p, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
    """(d tau / d q, d tau / d qd)."""
    model, data = build(arm, p)
    dq, dv, _ = pin.computeRNEADerivatives(model, data, _v(q), _v(qd), _v(qdd))
    return dq.copy(), dv.copy()


def aba_derivatives(arm: Arm, p, q, qd, tau) -> tuple[np.ndarray, np.ndarray]:
    """(d qdd / d q, d qdd / d qd)."""
    model, data = build(arm, p)
    dq, dv, _ = pin.computeABADerivatives(model, data, _v(q), _v(qd), _v(tau))
    return dq.copy(), dv.copy()


class Batch:
    """The same algorithms on one model built once, for many states (a python loop over
    Pinocchio's C++ calls: tens of microseconds a state)."""

    def __init__(self, arm: Arm, p):
        self.model, self.data = build(arm, p)

    def each(self, fn, *arrays) -> np.ndarray:
        """fn(model, data, *row) for the rows of the (T, N) arrays, stacked; tuples stacked apiece."""
        out = [fn(self.model, self.data, *map(_v, row)) for row in zip(*arrays)]
        if isinstance(out[0], tuple):
            return tuple(np.array([o[k] for o in out]) for k in range(len(out[0])))
        return np.array(out)

    def coriolis_matrix(self, Q, QD):
        return self.each(lambda m, d, q, qd: pin.computeCoriolisMatrix(m, d, q, qd).copy(), Q, QD)

    def forward_dynamics(self, Q, QD, TAU):
        return self.each(lambda m, d, q, qd, tau: pin.aba(m, d, q, qd, tau).copy(), Q, QD, TAU)

    def rnea(self, Q, QD, QDD):
        return self.each(lambda m, d, q, qd, qdd: pin.rnea(m, d, q, qd, qdd).copy(), Q, QD, QDD)

    def rnea_derivatives(self, Q, QD, QDD):
        """(T, N, 2N): [d tau / d q | d tau / d qd] per state."""
        def one(m, d, q, qd, qdd):
            dq, dv, _ = pin.computeRNEADerivatives(m, d, q, qd, qdd)
            return np.hstack([dq, dv])
        return self.each(one, Q, QD, QDD)

    def aba_derivatives(self, Q, QD, TAU):
        """(T, N, 2N): [d qdd / d q | d qdd / d qd] per state."""
        def one(m, d, q, qd, tau):
            dq, dv, _ = pin.computeABADerivatives(m, d, q, qd, tau)
            return np.hstack([dq, dv])
        return self.each(one, Q, QD, TAU)
