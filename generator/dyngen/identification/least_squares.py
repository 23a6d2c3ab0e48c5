"""Ordinary least squares with its condition number, a textbook standard deviation per coefficient
(std_k = sqrt(sigma^2 [(A^T A)^-1]_kk): a lower bound for correlated residuals), and the
coefficients not excited (loading over half on directions below `weak` of the largest singular
value, columns at unit norm), solved in the minimum-norm sense and flagged."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

WEAK = 1e-4  # relative singular value below which a direction counts as not excited


@dataclass
class Estimate:
    names: list[str]  # coefficient expressions
    values: np.ndarray
    std: np.ndarray  # inf where not excited
    condition: float  # condition number of A (columns as they are)
    scaled_condition: float  # with every column scaled to unit norm
    residual_rms: float
    rows: int
    unexcited: list[int]  # indices of coefficients the data do not excite

    def warnings(self) -> list[str]:
        return [f"the data do not excite coefficient {k} ({self.names[k]}); its value is not determined"
                for k in self.unexcited]


def fit_factor(R: np.ndarray, rows: int, names: list[str], weak: float = WEAK) -> Estimate:
    """The fit of `rows` rows whose [A | b] has the triangular factor R: A's singular values and vectors
    are those of R's first c columns, U^T b comes through its last, |b - A x| = |R (x, -1)|."""
    c = R.shape[1] - 1
    A, b = R[:, :c], R[:, c]
    norms = np.linalg.norm(A, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    U, sv, Vt = np.linalg.svd(A / scale, full_matrices=False)
    strong = sv > weak * sv[0]
    # Minimum-norm solution in the scaled variables over the excited directions only.
    x = Vt[strong].T @ ((U[:, strong].T @ b) / sv[strong]) / scale
    sse = float(np.sum((R @ np.r_[x, -1.0]) ** 2))
    sigma2 = sse / max(rows - int(strong.sum()), 1)
    loading = (Vt[~strong] ** 2).sum(axis=0)  # share of each coefficient in the weak directions
    unexcited = [k for k in range(c) if loading[k] > 0.5 or norms[k] == 0]
    std = np.sqrt(sigma2 * np.diag((Vt[strong].T / sv[strong] ** 2) @ Vt[strong])) / scale
    std[unexcited] = np.inf
    raw = np.linalg.svd(A, compute_uv=False)
    condition = float(raw[0] / raw[-1]) if raw[-1] > 0 else float("inf")
    scaled_condition = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    return Estimate(list(names), x, std, condition, scaled_condition, float(np.sqrt(sse / max(rows, 1))), rows,
                    unexcited)
