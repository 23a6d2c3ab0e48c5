"""What the data themselves say a rigid body can explain, whatever the link parameters: the torque left
after a least-squares fit of the base coefficients with a per-joint offset, Coulomb and viscous friction
(each joint's rows scaled by its torque, so that a wrist counts as much as the shoulder). Where the
nominal residual is above the torque but this fit explains the data, the conditioning is sound and the
link parameters are what is off (data/trust.py).

    residual = rigid_fit_residual(model, signals)      # (N,) RMS per joint"""

from __future__ import annotations

import numpy as np

SAMPLES = 4000  # evenly spread samples fitted: a few coefficients per joint, thousands of rows
VELOCITY = 0.02  # rad/s: the friction's tanh scale (the simple model's)


def rigid_fit_residual(model, sig) -> np.ndarray:
    keep = np.flatnonzero(sig.inner())
    rows = keep[np.linspace(0, keep.size - 1, min(SAMPLES, keep.size)).astype(int)]
    q, qd, qdd, tau = sig.q[rows], sig.qd[rows], sig.qdd[rows], sig.tau[rows]
    t, n = tau.shape
    body = model.batch("regressor", q, qd, qdd)  # (T, N, coefficients)
    friction = np.zeros((t, n, 3 * n))
    for j in range(n):
        friction[:, j, 3 * j:3 * j + 3] = np.column_stack([np.ones(t), np.tanh(qd[:, j] / VELOCITY), qd[:, j]])
    scale = np.maximum(np.sqrt(np.mean(tau ** 2, axis=0)), 1e-12)
    a = (np.concatenate([body, friction], axis=2) / scale[None, :, None]).reshape(t * n, -1)
    x = np.linalg.lstsq(a, (tau / scale).reshape(-1), rcond=None)[0]
    left = tau - (a @ x).reshape(t, n) * scale
    return np.sqrt(np.mean(left ** 2, axis=0))
