"""The low-pass cutoff for differentiating recorded positions, decided from the recording.

Encoders give positions with noise (and quantisation) of about 1e-5 rad; central differences
turn it into accelerations noisy by tens of rad/s^2 at 500 Hz. A zero-phase low-pass of
cutoff fc leaves, for white position noise sigma_q at sampling rate fs, an acceleration noise

    sigma_qdd(fc) = sigma_q (2 pi)^2 sqrt(fc^5 / (5 fs / 2))        (ideal low-pass)

so the cutoff is the largest one whose acceleration noise stays below NOISE_SHARE of the
motion's own acceleration (RMS over the joints): higher would let noise into the model
torques, lower would throw away motion that the diagnosis can use. Both numbers come from the
recording:

  - sigma_q per joint from the third differences of q (white noise of sigma gives differences
    of sigma sqrt(20); the motion's third difference is negligible at these rates), with a
    robust (median) scale so that steps of the motion do not count as noise;
  - the motion's acceleration RMS from q differentiated through the cutoff itself (the
    noise part, predicted by the formula, removed), iterated a few times from fs / 20.

The motion's band (the frequency under which 99 % of its velocity power lies, from the
spectrum of the differentiated positions) is reported beside it: a cutoff below twice the band
means that the position noise limits what can be seen, and the diagnosis says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .noise_floor import spectral_noise

NOISE_SHARE = 0.003  # acceleration noise allowed, relative to the motion's acceleration RMS
MAX_FRACTION = 0.2  # the cutoff stays below this fraction of the sampling rate
MIN_CUTOFF = 0.5  # Hz
HEAVY_TAILS = 1.5  # the spectrum's noise is used when it exceeds the robust estimate by this factor
NO_FILTER_NOISE = 1e-12  # rad: positions this clean are differentiated without a filter


@dataclass(frozen=True)
class Decision:
    cutoff: float | None  # Hz; None: no filter needed
    q_noise: np.ndarray  # per joint position noise sigma [rad]
    qdd_noise: np.ndarray  # per joint predicted acceleration noise after the filter [rad/s^2]
    band: float  # Hz: 99 % of the motion's velocity power lies below


def position_noise(q: np.ndarray) -> np.ndarray:
    """Per joint sigma of white noise on q, from robust third differences; where the spectrum
    shows clearly more broadband error than that (a logger's late or repeated samples, a coarse
    encoder's steps: noise_floor.py), the spectrum's."""
    if q.shape[0] < 8:
        return np.zeros(q.shape[1])
    d3 = np.diff(q, n=3, axis=0)
    mad = np.median(np.abs(d3 - np.median(d3, axis=0)), axis=0)
    robust = 1.4826 * mad / np.sqrt(20.0)
    broadband = spectral_noise(q)
    return np.where(broadband > HEAVY_TAILS * robust, broadband, robust)


def acceleration_noise(sigma_q, cutoff: float, rate: float, order: int = 2) -> np.ndarray:
    """After `order` differentiations (2 from positions, 1 from recorded velocities)."""
    return np.asarray(sigma_q) * (2 * np.pi) ** order * np.sqrt(cutoff ** (2 * order + 1) / ((2 * order + 1) * rate / 2))


def motion_band(qd: np.ndarray, rate: float) -> float:
    """Frequency under which 99 % of the velocity power (summed over joints) lies."""
    x = qd - qd.mean(axis=0)
    power = (np.abs(np.fft.rfft(x * np.hanning(x.shape[0])[:, None], axis=0)) ** 2).sum(axis=1)
    f = np.fft.rfftfreq(x.shape[0], 1.0 / rate)
    cumulative = np.cumsum(power)
    if cumulative[-1] <= 0:
        return 0.0
    return float(f[min(np.searchsorted(cumulative, 0.99 * cumulative[-1]), f.size - 1)])


def decide(t: np.ndarray, q: np.ndarray, lowpass_of, order: int = 2) -> Decision:
    """lowpass_of(cutoff) -> a function filtering (T, ...) arrays along time. order 1: q are
    recorded velocities, differentiated once (their noise measured the same way)."""
    rate = 1.0 / float(np.median(np.diff(t)))
    sigma = position_noise(q)

    def derivatives(x):
        qd = np.gradient(x, t, axis=0) if order == 2 else x
        return qd, np.gradient(qd, t, axis=0)

    if q.shape[0] < 32 or float(sigma.max()) <= NO_FILTER_NOISE:
        band = motion_band(derivatives(q)[0], rate) if q.shape[0] >= 32 else 0.0
        return Decision(None, sigma, np.zeros_like(sigma), band)
    noise = float(np.sqrt(np.mean(sigma ** 2)))
    top = MAX_FRACTION * rate
    cutoff = rate / 20
    for _ in range(6):  # converges in two or three steps: the RMS changes slowly with the cutoff
        qd, qdd = derivatives(lowpass_of(cutoff)(q))
        measured = float(np.mean(qdd ** 2))
        signal = np.sqrt(max(measured - float(np.mean(acceleration_noise(sigma, cutoff, rate, order) ** 2)), 0.0))
        # the largest fc with noise(fc) <= NOISE_SHARE * signal
        target = NOISE_SHARE * max(signal, 1e-12)
        k = 2 * order + 1
        new = (target / (noise * (2 * np.pi) ** order)) ** (2 / k) * (k * rate / 2) ** (1 / k)
        new = float(np.clip(new, MIN_CUTOFF, top))
        if abs(new - cutoff) <= 0.01 * cutoff:
            cutoff = new
            break
        cutoff = new
    qd = derivatives(lowpass_of(cutoff)(q))[0]
    return Decision(cutoff, sigma, acceleration_noise(sigma, cutoff, rate, order), motion_band(qd, rate))
