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
