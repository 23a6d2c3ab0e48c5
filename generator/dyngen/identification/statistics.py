"""What a user needs to trust the identified values: a standard deviation per column that holds
for real data, the condition numbers, and the columns the data do not excite.

The values are those of the unconstrained weighted least squares of the same columns (rows of
joint j weighted by 1 / sigma_j), through the normal equations of unit-norm columns
(normal.py); a column is *not excited* when it loads by more than half on directions whose
singular value is below WEAK times the largest (least_squares.py).

Standard deviations. The textbook (A^T W A)^-1 sigma^2 assumes residuals independent from sample
to sample. Filtered and differentiated signals are not: the residual of a 10 Hz filtered
recording at 1 kHz is correlated over tens of samples, and the textbook deviation is too small
by the square root of that correlation time. The deviation reported is the sandwich (batch
means) estimate

    Cov(x) = H^-1 S H^-1,   H = A^T W A,   S = sum_b s_b s_b^T,   s_b = sum_{t in block b} a_t w_t e_t

over contiguous blocks b of BLOCK_TIMES integrated autocorrelation times of the residual
(data/correlation.py's estimate, the largest over joints), at least MIN_BLOCKS of them:
the scores' variance as the data show it, whatever the residual's correlation, its change of
size along the motion, or a model error that comes and goes with the motion (a sticking joint at
rest). Where the data are too short for MIN_BLOCKS such blocks, the textbook deviation scaled by
the square root of the correlation time is reported instead. Either way never below the
textbook deviation.
"""

from __future__ import annotations

import numpy as np

from ..data.correlation import integrated_time
from .least_squares import WEAK, Estimate
from .normal import joint_design, local_labels

BLOCK_TIMES = 20  # block length in integrated autocorrelation times of the residual
MIN_BLOCKS = 10


def residuals(pieces, labels, r: int, x: np.ndarray, keep: np.ndarray, dof: int) -> list:
    """Per piece (T, N): measured less fitted torque for the values x of the columns keep."""
    full = np.zeros(r + len(labels))
    full[keep] = x
    out = []
    for piece in pieces:
        e = piece.tau.copy()
        for j in range(dof):
            ks = local_labels(labels, j)
            e[:, j] -= joint_design(piece, labels, j, ks) @ full[np.r_[np.arange(r), r + np.asarray(ks, dtype=int)]]
        out.append(e)
    return out


def _scores(pieces, labels, r, keep, weights, res, length: int, dof: int) -> np.ndarray:
    """(blocks, len(keep)): per contiguous block of `length` samples of each piece, sum_t a_t w e_t."""
    c = r + len(labels)
    out = []
    for piece, e in zip(pieces, res):
        T = e.shape[0]
        starts = np.arange(0, T - length + 1, length)
        if starts.size == 0:
            continue
        s = np.zeros((starts.size, c))
        for j in range(dof):
            ks = local_labels(labels, j)
            idx = np.r_[np.arange(r), r + np.asarray(ks, dtype=int)]
            A = joint_design(piece, labels, j, ks)[:starts[-1] + length]
            weighted = A * (weights[j] ** 2 * e[:starts[-1] + length, j])[:, None]
            s[:, idx] += np.add.reduceat(weighted, starts, axis=0)
        out.append(s[:, keep])
    return np.vstack(out) if out else np.zeros((0, len(keep)))


def estimate(normal, parts, weights, pieces, names, keep, dof: int) -> Estimate:
    """The weighted unconstrained fit of the columns keep (indices into coefficients, then
    labels) on the given parts, with standard deviations as above."""
    G, g = normal.total(parts, weights, keep)
    cols = len(keep)
    norms = np.sqrt(np.maximum(np.diag(G), 0.0))
    scale = np.where(norms > 0, norms, 1.0)
    ev, V = np.linalg.eigh(G / np.outer(scale, scale))
    ev, V = ev[::-1], V[:, ::-1]
    sv = np.sqrt(np.maximum(ev, 0.0))
    strong = sv > WEAK * sv[0]
    inverse = (V[:, strong] / ev[strong]) @ V[:, strong].T / np.outer(scale, scale)  # H^-1 on the excited directions
    x = inverse @ g
    rows = int(normal.n[parts].sum())
    fit_pieces = [p for p in pieces if np.isin(p.part, parts).all()]
    res = residuals(fit_pieces, normal.labels, normal.r, x, keep, dof)
    weighted = np.concatenate([(e * weights).reshape(-1) for e in res])
    sigma2 = float(weighted @ weighted) / max(rows - int(strong.sum()), 1)
    textbook = np.sqrt(np.maximum(sigma2 * np.diag(inverse), 0.0))
    times = [integrated_time(e[:, j]) for e in res for j in range(dof) if e.shape[0] > 8]
    tau = max(times) if times else 1.0
    length = int(np.ceil(BLOCK_TIMES * tau))
    scores = _scores(fit_pieces, normal.labels, normal.r, keep, weights, res, length, dof)
    if scores.shape[0] >= MIN_BLOCKS:
        sandwich = np.einsum("ab,kb->ka", inverse, scores)
        std = np.maximum(np.sqrt((sandwich ** 2).sum(axis=0)), textbook)
    else:
        std = textbook * np.sqrt(tau)
    loading = (V[:, ~strong].T ** 2).sum(axis=0)
    unexcited = [k for k in range(cols) if loading[k] > 0.5 or norms[k] == 0]
    std[unexcited] = np.inf
    raw = np.sqrt(np.maximum(np.linalg.eigvalsh(G), 0.0))
    condition = float(raw[-1] / raw[0]) if raw[0] > 0 else float("inf")
    scaled = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    return Estimate(list(names), x, std, condition, scaled, float(np.sqrt(np.mean(weighted ** 2))), rows, unexcited)
