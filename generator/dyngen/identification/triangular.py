"""Least squares accumulated block by block, per joint: the rows [A_j | b_j] folded into the
triangular factor of their QR, R_j <- triu(qr([R_j; A_block b_block])), all a fit needs
(least_squares.fit_factor), memory independent of the row count; factors stack the same way."""

from __future__ import annotations

import numpy as np


def fold(R: np.ndarray | None, rows: np.ndarray) -> np.ndarray:
    """The (c+1, c+1) factor of R's rows and `rows` (k, c+1) together."""
    stacked = rows if R is None else np.vstack([R, rows])
    if stacked.shape[0] < stacked.shape[1]:  # fewer rows than columns: keep them as they are
        return stacked
    return np.linalg.qr(stacked, mode="r")


class Triangular:
    """Per-joint factors of [A_j | b_j] and row counts, for c columns and `dof` joints."""

    def __init__(self, columns: int, dof: int):
        self.c, self.dof = columns, dof
        self.R = [None] * dof
        self.rows = np.zeros(dof, dtype=np.int64)

    def add(self, Y: np.ndarray, b: np.ndarray) -> None:
        """Y (T, dof, c) the regressor rows of T samples, b (T, dof) their measurements."""
        for j in range(self.dof):
            self.R[j] = fold(self.R[j], np.column_stack([Y[:, j, :], b[:, j]]))
            self.rows[j] += b.shape[0]

    def merged(self, other: "Triangular") -> "Triangular":
        out = Triangular(self.c, self.dof)
        for j in range(self.dof):
            parts = [R for R in (self.R[j], other.R[j]) if R is not None]
            out.R[j] = fold(None, np.vstack(parts)) if parts else None
        out.rows = self.rows + other.rows
        return out

    def factor(self) -> np.ndarray:
        return fold(None, np.vstack([self._full(j) for j in range(self.dof)]))

    def _full(self, j) -> np.ndarray:
        R = self.R[j]
        if R is None:
            return np.zeros((0, self.c + 1))
        return R

    def sse(self, x: np.ndarray) -> np.ndarray:
        """(dof,): each joint's sum of squared residuals |b_j - A_j x|^2."""
        v = np.r_[x, -1.0]
        return np.array([float(np.sum((self._full(j) @ v) ** 2)) for j in range(self.dof)])
