"""Position noise from the spectrum: the errors a robust scale does not see.

A logger's late samples sit qd * delay off the motion on a few per cent of the rows: invisible to
the median of the third differences, decisive after differentiation. Their energy is broadband:
for white noise of sigma the third difference has the power density sigma^2 (2 sin(pi f / fs))^6,
so the median over the upper band divided by that shape is sigma^2 whatever the errors' shape."""

from __future__ import annotations

import numpy as np

BAND_FROM = 0.25  # of the sampling rate: the band whose median power is the floor (up to 0.5)
MEDIAN_OF_CHI2_2 = np.log(2.0)  # median / mean of a periodogram bin (chi-square, 2 degrees of freedom)


def spectral_noise(q: np.ndarray) -> np.ndarray:
    """Per joint sigma of the broadband position errors, from the third differences' spectrum."""
    x = np.diff(np.asarray(q, dtype=float), n=3, axis=0)
    if x.shape[0] < 64:
        return np.zeros(q.shape[1])
    window = np.hanning(x.shape[0])
    power = np.abs(np.fft.rfft((x - x.mean(axis=0)) * window[:, None], axis=0)) ** 2 / np.sum(window ** 2)
    f = np.fft.rfftfreq(x.shape[0])  # cycles per sample
    band = (f >= BAND_FROM) & (f > 0)
    shape = (2.0 * np.sin(np.pi * f[band])) ** 6
    return np.sqrt(np.median(power[band] / shape[:, None], axis=0) / MEDIAN_OF_CHI2_2)
