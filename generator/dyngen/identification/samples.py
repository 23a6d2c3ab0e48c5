"""Stacked regressors and measurements of eq. (11), from conditioned recordings.

kind "gravity":  Y_g(q_k) pi_g = tau_k, the recordings' torques read as gravity torques
                 (static poses, or the FRI's g(q) as in the paper, eq. 9);
kind "inertia":  Y_m(q_k) pi_m = m~_k, the stacked inertia matrix in columns M11, M12, ...
                 (the FRI's M(q), eq. 10);
kind "full":     Y(q_k, qd_k, qdd_k) pi = tau_k, torque trajectories.
The generated C regressors are evaluated in batch through dyngen.runtime.
"""

from __future__ import annotations

import numpy as np

from ..catalogue import REGRESSORS
from ..errors import InputError
from .least_squares import Estimate, fit

REGRESSOR = {kind: f.name for kind, f in REGRESSORS.items()}


def stacked_inertia_columns(manifest) -> list[str]:
    return list(manifest["stacked_inertia_order"])


def stacked(model, signals: list, kind: str) -> tuple[np.ndarray, np.ndarray]:
    """(A, b): the regressor rows of every sample of every recording, and the measurements."""
    if kind not in REGRESSOR:
        raise ValueError(f"unknown kind {kind!r}; expected one of {', '.join(REGRESSOR)}")
    blocks, values = [], []
    for s in signals:
        if kind == "gravity":
            Y, b = model.batch(REGRESSOR[kind], s.q), s.tau
        elif kind == "inertia":
            names = stacked_inertia_columns(model.manifest)
            missing = [c for c in names if c not in s.extra]
            if missing:
                raise InputError(s.name, "line 1 (header)", f"missing column(s) {', '.join(missing)} "
                                 "(stacked inertia matrix, needed for --kind inertia)")
            Y, b = model.batch(REGRESSOR[kind], s.q), np.column_stack([s.extra[c] for c in names])
        else:
            Y, b = model.batch(REGRESSOR[kind], s.q, s.qd, s.qdd), s.tau
        blocks.append(Y.reshape(-1, Y.shape[-1]))
        values.append(np.asarray(b).reshape(-1))
    return np.vstack(blocks), np.concatenate(values)


def identify(model, signals: list, kind: str) -> Estimate:
    A, b = stacked(model, signals, kind)
    names = [e["standard"] for e in model.manifest["coefficients"][kind]["expressions"]]
    files = ", ".join(s.name for s in signals)
    if A.shape[0] <= A.shape[1]:
        per_sample = A.shape[0] // max(sum(len(s.t) for s in signals), 1) or 1
        raise InputError(files, "", f"under-determined: {A.shape[0]} equations for {A.shape[1]} {kind} "
                         f"coefficients; record at least {A.shape[1] // per_sample + 1} samples (many more, "
                         "on an exciting trajectory, for a usable estimate)")
    try:
        return fit(A, b, names)
    except np.linalg.LinAlgError as err:
        raise InputError(files, "", f"least squares failed ({err}); check the recordings for extreme values") from None
