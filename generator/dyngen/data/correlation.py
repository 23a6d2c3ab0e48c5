"""How many independent samples a correlated residual is worth: least-squares deviations are scaled
by sqrt(tau), the integrated autocorrelation time tau = 1 + 2 sum_k rho_k in samples, summed until
rho first drops below 0.05."""

from __future__ import annotations

import numpy as np


def integrated_time(x: np.ndarray) -> float:
    x = np.asarray(x, dtype=float)
    x = x - x.mean()
    n = x.size
    if n < 4 or not np.any(x):
        return 1.0
    size = 1 << int(np.ceil(np.log2(2 * n)))
    spectrum = np.fft.rfft(x, size)
    acf = np.fft.irfft(spectrum * np.conj(spectrum), size)[:n]
    return truncated(acf / acf[0], min(n - 1, n // 4))


def truncated(rho: np.ndarray, limit: int) -> float:
    """1 + 2 sum_k rho_k over k = 1 .. limit, up to where rho first drops below 0.05."""
    below = np.flatnonzero(rho[1:limit + 1] < 0.05)
    stop = below[0] + 1 if below.size else limit + 1
    return float(max(1.0, 1.0 + 2.0 * rho[1:stop].sum()))
