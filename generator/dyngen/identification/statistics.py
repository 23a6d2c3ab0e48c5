"""What a user needs to trust the identified values, from the unconstrained weighted fit of the same
columns: the sandwich (batch means) deviation H^-1 S H^-1 over blocks of BLOCK_TIMES correlation
times (at least MIN_BLOCKS; never below the textbook one), condition numbers, unexcited columns."""

from __future__ import annotations

import numpy as np
from scipy import fft, signal

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
        # one matrix-vector product per joint; or the model's inverse dynamics at the coefficients,
        # where the pass computed no regressor (blocks.Blocks.rigid: the correlation time's pass)
        e = piece.tau - (piece.Yj @ full[:r]).T if piece.Yj is not None else piece.tau - piece.rigid
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

    def add(self, x: np.ndarray, products=None) -> None:
        """products: _lag_products' column of this series, if made with the others'."""
        z = np.r_[np.zeros(LAGS - self.tail.size), self.tail, x]
        self.products += signal.correlate(z, x, mode="valid")[::-1] if products is None else products
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


def _lag_products(series: list, x: np.ndarray) -> np.ndarray:
    """(LAGS + 1, N): [k, j] = sum_t x_tj x_(t-k)j over this block's t, the samples before it from
    series[j]'s tail: every column in one real FFT of the block's length and LAGS (circular, no
    wrap for lags up to LAGS), not one linear correlation per column (2x the length)."""
    z = np.vstack([np.column_stack([np.r_[np.zeros(LAGS - c.tail.size), c.tail] for c in series]), x])
    size = fft.next_fast_len(z.shape[0], real=True)
    c = fft.irfft(fft.rfft(z, size, axis=0) * np.conj(fft.rfft(x, size, axis=0)), size, axis=0)
    return c[LAGS::-1]  # c[m] = sum_t z_(t+m) x_t, z_(t+LAGS-k) = x_(t-k)


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


class _score_blocks:
    """The sum over blocks of s s^T and their count, of contiguous blocks of `length` score rows per
    recording counted from its first sample: each file block's partial sums (made where its rows are,
    partial()) added in block order, a score block straddling two file blocks carried over."""

    def __init__(self, length: int):
        self.length, self.S, self.count = length, 0.0, 0
        self.current, self.index, self.open = None, -1, None

    def partial(self, rows: np.ndarray, start: int) -> tuple:
        """(score block numbers, their sums over these rows): the rows' first sample is `start`."""
        at = (start + np.arange(rows.shape[0])) // self.length
        starts = np.r_[0, np.flatnonzero(np.diff(at)) + 1]
        return at[starts], np.add.reduceat(rows, starts)

    def add(self, source, numbers, parts) -> None:
        if source is not self.current:
            self.close()
            self.current, self.index, self.open = source, -1, None
        for number, part in zip(numbers, parts):
            if number == self.index:
                self.open = self.open + part
            else:
                self.close()
                self.index, self.open = number, part

    def close(self) -> None:
        if self.open is not None and (self.index + 1) * self.length <= self.current.rows:
            self.S, self.count = self.S + np.outer(self.open, self.open), self.count + 1


def _source_of(blocks, piece) -> int:
    return next(i for i, s in enumerate(blocks.sources) if s is piece.source)


def estimate(normal, parts, weights, blocks, names, keep, dof: int) -> Estimate:
    """The weighted unconstrained fit of the columns keep on the parts, with the deviations above: two
    passes over the blocks (the residuals' correlation time, from the inverse dynamics at x without the
    regressor; then the residuals' size and the score rows, summed over the blocks of BLOCK_TIMES
    correlation times where each file block is made: nothing per sample is kept)."""
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
    sse, correlation = 0.0, {}

    def of_fit(piece):  # the fit parts' blocks only (a select recording's are not)
        return np.isin(piece.part, parts).all()

    def residual(piece):
        return (_source_of(blocks, piece), residuals([piece], labels, r, x, keep)[0]) if of_fit(piece) else None

    # the residuals' correlation time: a pass that needs Y x only (the inverse dynamics at x, no regressor)
    full = np.zeros(r + len(labels))
    full[keep] = x
    blocks.rigid = full[:r] if hasattr(blocks.model, "inverse_dynamics") else None
    try:
        for at, e in filter(None, blocks.each(residual)):
            series = [correlation.setdefault((at, j), _Correlation()) for j in range(dof)]
            for j, products in enumerate(_lag_products(series, e).T):  # the series' tails before the block's
                series[j].add(e[:, j], products)
    finally:
        blocks.rigid = None
    times = [c.time() for c in correlation.values() if c.n > 8]
    tau = max(times) if times else 1.0
    batches = _score_blocks(int(np.ceil(BLOCK_TIMES * tau)))

    def scored(piece):  # a fit block's residuals and score rows, summed over its score blocks where it is made
        if not of_fit(piece):
            return None
        e = residuals([piece], labels, r, x, keep)[0]
        rows = _score_rows(piece, labels, r, weights, e)[:, keep]
        return (_source_of(blocks, piece), float(((e * weights) ** 2).sum()), *batches.partial(rows, piece.start))

    for at, squares, numbers, sums in filter(None, blocks.each(scored)):
        sse += squares
        batches.add(blocks.sources[at], numbers, sums)
    batches.close()
    S, count = batches.S, batches.count
    sigma2 = sse / max(rows - int(strong.sum()), 1)
    textbook = np.sqrt(np.maximum(sigma2 * np.diag(inverse), 0.0))
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
