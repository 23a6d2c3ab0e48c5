"""The low-pass cutoff for differentiating recorded positions, decided from the recording: the
largest whose acceleration noise, sigma_q (2 pi)^2 sqrt(fc^5 / (5 fs / 2)) for white position noise
sigma_q at rate fs, stays below NOISE_SHARE of the motion's acceleration RMS (docs/measured-data.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NOISE_SHARE = 0.003  # acceleration noise allowed, relative to the motion's acceleration RMS
MAX_FRACTION = 0.2  # the cutoff stays below this fraction of the sampling rate
MIN_CUTOFF = 0.5  # Hz
HEAVY_TAILS = 1.5  # the spectrum's noise is used when it exceeds the robust estimate by this factor
NO_FILTER_NOISE = 1e-12  # rad: positions this clean are differentiated without a filter
BAND_FROM = 0.25  # of the sampling rate: the band whose median power is the spectral noise floor (up to 0.5)
MEDIAN_OF_CHI2_2 = np.log(2.0)  # median / mean of a periodogram bin (chi-square, 2 degrees of freedom)
COLOURED = 2.0  # noise between twice the cutoff and the decision's band this many times its sigma: not white


@dataclass(frozen=True)
class Decision:
    cutoff: float | None  # Hz; None: no filter needed
    q_noise: np.ndarray  # per joint position noise sigma [rad]
    qdd_noise: np.ndarray  # per joint predicted acceleration noise after the filter [rad/s^2]
    band: float  # Hz: 99 % of the motion's velocity power lies below


def position_noise(q: np.ndarray, rows=None) -> np.ndarray:
    """Per joint white-noise sigma of q from robust third differences, or the spectrum's where larger.
    rows: boolean (T - 3,), the third differences of data samples alone (None: all; see decide)."""
    if q.shape[0] < 8:
        return np.zeros(q.shape[1])
    d3 = np.diff(q, n=3, axis=0)
    d3 = d3 if rows is None else d3[rows]
    mad = np.median(np.abs(d3 - np.median(d3, axis=0)), axis=0)
    robust = 1.4826 * mad / np.sqrt(20.0)
    broadband = spectral_noise(q, rows)
    return np.where(broadband > HEAVY_TAILS * robust, broadband, robust)


def spectral_noise(q: np.ndarray, rows=None) -> np.ndarray:
    """Per joint sigma of the broadband position errors, which a robust scale does not see (a
    logger's late samples sit qd * delay off the motion on a few per cent of the rows): for white
    noise of sigma the third difference's power density is sigma^2 (2 sin(pi f / fs))^6, so its
    median over the upper band divided by that shape is sigma^2 whatever the errors' shape."""
    x = np.diff(np.asarray(q, dtype=float), n=3, axis=0)
    if x.shape[0] < 64:
        return np.zeros(q.shape[1])
    window = np.hanning(x.shape[0])
    if rows is None:
        power = np.abs(np.fft.rfft((x - x.mean(axis=0)) * window[:, None], axis=0)) ** 2 / np.sum(window ** 2)
    else:  # the other rows zero: the power of white noise is its sigma^2 times the window's weight on the rows
        x = np.where(rows[:, None], x - x[rows].mean(axis=0), 0.0)
        power = np.abs(np.fft.rfft(x * window[:, None], axis=0)) ** 2 / np.sum(window[rows] ** 2)
    f = np.fft.rfftfreq(x.shape[0])  # cycles per sample
    band = (f >= BAND_FROM) & (f > 0)
    shape = (2.0 * np.sin(np.pi * f[band])) ** 6
    return np.sqrt(np.median(power[band] / shape[:, None], axis=0) / MEDIAN_OF_CHI2_2)


def coloured(q: np.ndarray, rate: float, cutoff: float, sigma: np.ndarray) -> bool:
    """Whether the noise of q (positions, or recorded velocities) between twice the cutoff and the
    band that position_noise measures (BAND_FROM of the rate) exceeds COLOURED times the white
    noise sigma found there, on most joints: no motion reaches that band, so it is noise the cutoff
    decision did not allow for (a polling logger's late stamps, made a regular grid, hold it below
    the upper band), and the accelerations carry more of it than the cutoff was chosen for. A
    model's torque formed of them carries it beyond the cutoff, where the filtered torque has
    none: that torque is filtered alike (a second pass then removes noise, not the motion's steps)."""
    x = np.diff(np.asarray(q, dtype=float), n=3, axis=0)
    f = np.fft.rfftfreq(x.shape[0], 1.0 / rate)
    band = (f >= 2.0 * cutoff) & (f < BAND_FROM * rate)
    if np.count_nonzero(band) < 16:
        return False
    window = np.hanning(x.shape[0])
    power = np.abs(np.fft.rfft((x - x.mean(axis=0)) * window[:, None], axis=0)[band]) ** 2 / np.sum(window ** 2)
    shape = (2.0 * np.sin(np.pi * f[band] / rate)) ** 6
    found = np.sqrt(np.median(power / shape[:, None], axis=0) / MEDIAN_OF_CHI2_2)
    return bool(np.median(found / np.maximum(sigma, 1e-300)) > COLOURED)


def acceleration_noise(sigma_q, cutoff: float, rate: float, order: int = 2) -> np.ndarray:
    """After `order` differentiations (2 from positions, 1 from recorded velocities)."""
    return np.asarray(sigma_q) * (2 * np.pi) ** order * np.sqrt(cutoff ** (2 * order + 1) / ((2 * order + 1) * rate / 2))


def motion_band(qd: np.ndarray, rate: float) -> float:
    """Frequency under which 99 % of the velocity power (summed over joints) lies."""
    x = qd - qd.mean(axis=0)
    power = (np.abs(np.fft.rfft(x * np.hanning(x.shape[0])[:, None], axis=0)) ** 2).sum(axis=1)
    f = np.fft.rfftfreq(x.shape[0], 1.0 / rate)
    cumulative = np.cumsum(power)
    return 0.0 if cumulative[-1] <= 0 else float(f[min(np.searchsorted(cumulative, 0.99 * cumulative[-1]), f.size - 1)])


def decide(t: np.ndarray, q: np.ndarray, lowpass_of, order: int = 2, data=None) -> Decision:
    """lowpass_of(cutoff) -> a filter along time; order 1: q are recorded velocities, differentiated once.
    data: boolean (T,), the samples that are data (None: all): the noise and the acceleration are
    measured on them alone, not on samples interpolated in a gap of the stamps (smooth: no noise)."""
    rate = 1.0 / float(np.median(np.diff(t)))
    rows = None if data is None else data[:-3] & data[1:-2] & data[2:-1] & data[3:]
    sigma = position_noise(q, rows)

    def derivatives(x):
        qd = np.gradient(x, t, axis=0) if order == 2 else x
        return qd, np.gradient(qd, t, axis=0)

    if q.shape[0] < 32 or float(sigma.max()) <= NO_FILTER_NOISE:
        return Decision(None, sigma, np.zeros_like(sigma), motion_band(derivatives(q)[0], rate) if q.shape[0] >= 32 else 0.0)
    noise = float(np.sqrt(np.mean(sigma ** 2)))
    cutoff = rate / 20
    for _ in range(6):  # converges in two or three steps: the RMS changes slowly with the cutoff
        qdd = derivatives(lowpass_of(cutoff)(q))[1]
        measured = float(np.mean(qdd ** 2)) if data is None else float(np.mean(qdd[data] ** 2))
        signal = np.sqrt(max(measured - float(np.mean(acceleration_noise(sigma, cutoff, rate, order) ** 2)), 0.0))
        # the largest fc with noise(fc) <= NOISE_SHARE * signal
        target = NOISE_SHARE * max(signal, 1e-12)
        k = 2 * order + 1
        new = float(np.clip((target / (noise * (2 * np.pi) ** order)) ** (2 / k) * (k * rate / 2) ** (1 / k),
                            MIN_CUTOFF, MAX_FRACTION * rate))
        cutoff, before = new, cutoff
        if abs(new - before) <= 0.01 * before:
            break
    qd = derivatives(lowpass_of(cutoff)(q))[0]
    return Decision(cutoff, sigma, acceleration_noise(sigma, cutoff, rate, order), motion_band(qd, rate))
