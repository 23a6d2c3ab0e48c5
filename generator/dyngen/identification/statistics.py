"""What a user needs to trust the identified values, from the unconstrained weighted fit of the same
columns: the sandwich (batch means) deviation H^-1 S H^-1 over blocks of BLOCK_TIMES correlation
times (at least MIN_BLOCKS; never below the textbook one), condition numbers, unexcited columns."""

from __future__ import annotations

import os
import tempfile

import numpy as np
from scipy import signal

from ..data.correlation import truncated
from .least_squares import WEAK, Estimate

BLOCK_TIMES = 20  # block length in integrated autocorrelation times of the residual
MIN_BLOCKS = 10
LAGS = 2048  # autocorrelation lags kept per recording and joint (the correlation time's sum)


def residuals(pieces, labels, r: int, x: np.ndarray, keep: np.ndarray) -> list:
    """Per piece (T, N): measured less fitted torque for the values x of the columns keep."""
    full = np.zeros(r + len(labels))
    full[keep] = x
    out = []
    for piece in pieces:
        e = piece.tau - (piece.Yj @ full[:r]).T  # one matrix-vector product per joint
        for k in np.flatnonzero(full[r:]):  # a joint's label in its own rows, the arm's in every joint's
            v = piece.columns[labels[k]]
            rows = e if v.ndim == 2 else e[:, labels[k][1]]  # a view: subtracted in place
            rows -= v * full[r + k]
        out.append(e)
    return out


class _Correlation:
    """data.correlation.integrated_time of a series given a block at a time."""

    def __init__(self):
        self.n, self.total = 0, 0.0
        self.products = np.zeros(LAGS + 1)
        self.head, self.tail = np.zeros(0), np.zeros(0)

    def add(self, x: np.ndarray) -> None:
        z = np.r_[np.zeros(LAGS - self.tail.size), self.tail, x]
        self.products += signal.correlate(z, x, mode="valid")[::-1]  # [k]: sum_t x_t x_(t-k), t in this block
        self.n, self.total = self.n + x.size, self.total + float(x.sum())
        self.head = np.r_[self.head, x[:LAGS + 1 - self.head.size]]
        self.tail = np.r_[self.tail, x][-LAGS:]

    def time(self) -> float:
        n = self.n
        if n < 4:
            return 1.0
        m, lags = self.total / n, min(n - 1, LAGS)
        k = np.arange(lags + 1)
        last = np.r_[0.0, np.cumsum(self.tail[::-1])][k]  # sums of the last k and the first k values
        first = np.r_[0.0, np.cumsum(self.head)][k]
        acf = self.products[k] - m * (2 * self.total - last - first) + (n - k) * m * m
        return truncated(acf / acf[0], min(lags, n // 4)) if acf[0] > 1e-24 * max(self.products[0], 1e-300) else 1.0


def _score_rows(piece, labels, r, weights, e) -> np.ndarray:
    """(T, c): per sample, sum over joints of a_t w_j^2 e_t (the fit's scores)."""
    we = weights ** 2 * e
    out = np.empty((e.shape[0], r + len(labels)))
    # one pass over the block's (T, N, r) regressor, joints summed in order, no (T, N, r) temporary:
    # 5x faster than joint by joint (a scaled copy of the rows and an addition per joint)
    np.einsum("tjr,tj->tr", piece.Yj.transpose(1, 0, 2), we, out=out[:, :r])
    for k, label in enumerate(labels):
        v = piece.columns[label]
        out[:, r + k] = (v * we).sum(axis=1) if v.ndim == 2 else v * we[:, label[1]]
    return out


def _score_blocks(spilled, length: int):
    """(sum over blocks of s s^T, count) of contiguous blocks of `length` score rows per recording."""
    S, count = 0.0, 0
    current, index, open_sum = None, -1, None

    def close():
        nonlocal S, count
        if open_sum is not None and (index + 1) * length <= current.rows:
            S, count = S + np.outer(open_sum, open_sum), count + 1

    for source, start, path in spilled:
        if source is not current:
            close()
            current, index, open_sum = source, -1, None
        rows = np.load(path)
        at = (start + np.arange(rows.shape[0])) // length
        starts = np.r_[0, np.flatnonzero(np.diff(at)) + 1]
        for number, part in zip(at[starts], np.add.reduceat(rows, starts)):
            if number == index:
                open_sum = open_sum + part
            else:
                close()
                index, open_sum = number, part
    close()
    return S, count


def estimate(normal, parts, weights, blocks, names, keep, dof: int) -> Estimate:
    """The weighted unconstrained fit of the columns keep on the parts, with the deviations above: two
    passes over the blocks (the residuals' size and correlation time; their score rows, kept in a
    temporary folder until the correlation time gives the blocks' length)."""
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
    labels, r = normal.labels, normal.r
    sse, correlation, spilled = 0.0, {}, []
    folder = tempfile.TemporaryDirectory(prefix="dyngen-scores-")

    def scored(piece):  # the residuals of a block of the fit parts, its score rows written (blocks.each)
        if not np.isin(piece.part, parts).all():
            return None
        e = residuals([piece], labels, r, x, keep)[0]
        at = (next(i for i, s in enumerate(blocks.sources) if s is piece.source), piece.start)
        np.save(os.path.join(folder.name, "%d-%d.npy" % at), _score_rows(piece, labels, r, weights, e)[:, keep])
        return at, e

    for at, e in filter(None, blocks.each(scored)):
        sse += float(((e * weights) ** 2).sum())
        for j in range(dof):
            correlation.setdefault((at[0], j), _Correlation()).add(e[:, j])
        spilled.append((blocks.sources[at[0]], at[1], os.path.join(folder.name, "%d-%d.npy" % at)))
    sigma2 = sse / max(rows - int(strong.sum()), 1)
    textbook = np.sqrt(np.maximum(sigma2 * np.diag(inverse), 0.0))
    times = [c.time() for c in correlation.values() if c.n > 8]
    tau = max(times) if times else 1.0
    with folder:
        S, count = _score_blocks(spilled, int(np.ceil(BLOCK_TIMES * tau)))
    if count >= MIN_BLOCKS:
        std = np.maximum(np.sqrt(np.maximum(np.diag(inverse @ S @ inverse), 0.0)), textbook)
    else:
        std = textbook * np.sqrt(tau)
    loading = (V[:, ~strong].T ** 2).sum(axis=0)
    unexcited = [k for k in range(cols) if loading[k] > 0.5 or norms[k] == 0]
    std[unexcited] = np.inf
    raw = np.sqrt(np.maximum(np.linalg.eigvalsh(G), 0.0))
    condition = float(raw[-1] / raw[0]) if raw[0] > 0 else float("inf")
    scaled = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    return Estimate(list(names), x, std, condition, scaled, float(np.sqrt(sse / max(rows, 1))), rows, unexcited)
