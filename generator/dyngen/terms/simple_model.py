"""The simple model every diagnosis is measured against: per joint r_j = b_j + Fc_j tanh(qd_j / 0.02)
+ Fv_j qd_j, fitted to the nominal residual on the fit samples (columns filtered like the torques).
A diagnosis worse than this on a joint keeps it there (diagnosis/joints.py)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .friction import SIMPLE_SCALE, Coulomb, Viscous, coulomb
from .sensor import Offset

VELOCITY = SIMPLE_SCALE  # rad/s: the simple model's tanh scale (fixed, not fitted)
NAMES = Offset.parameters + Coulomb.parameters + Viscous.parameters  # b, Fc, Fv: its columns' order


@dataclass
class Simple:
    values: np.ndarray  # (N, 3): b, Fc, Fv per joint


_CACHE: dict = {}  # id(signals) -> (signals, columns): the columns are asked for per joint and role


def columns(signals) -> np.ndarray:
    """(T, N, 3), computed once per recording."""
    hit = _CACHE.get(id(signals))
    if hit is not None and hit[0] is signals:
        return hit[1]
    qd = signals.qd
    out = np.stack([np.ones_like(qd), signals.filtered(coulomb(qd, VELOCITY)), qd], axis=-1)
    if len(_CACHE) > 16:  # recordings of earlier diagnoses
        _CACHE.clear()
    _CACHE[id(signals)] = (signals, out)
    return out


def fit(segments) -> Simple:
    n = segments[0].residual.shape[1]
    G, b = np.zeros((n, 3, 3)), np.zeros((n, 3))
    for seg in segments:
        if seg.fit.any():
            A = columns(seg.signals)[seg.fit]
            G += np.einsum("tjk,tjl->jkl", A, A)
            b += np.einsum("tjk,tj->jk", A, seg.residual[seg.fit])
    return Simple(np.array([np.linalg.lstsq(G[j], b[j], rcond=1e-12)[0] for j in range(n)]))


def predict(simple: Simple, seg) -> np.ndarray:
    return np.einsum("tjk,jk->tj", columns(seg.signals), simple.values)
