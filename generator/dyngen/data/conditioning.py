"""Signal conditioning as in the paper (Sec. IV): velocities and accelerations by numerical
differentiation of q, and a zero-phase Butterworth low-pass applied alike to positions and
torques, so that no signal is shifted in time against another.

Choices: the filter runs forwards and backwards (scipy sosfiltfilt), so its order doubles in
effect and its phase is zero; the sampling rate is the median rate (recordings with jitter
are treated as uniformly sampled). When a file has its own qd (and qdd), they are used
unless `differentiate` is set; if a cutoff is given they are filtered like the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from ..errors import InputError
from .recording import Recording


@dataclass(frozen=True)
class Conditioning:
    cutoff: float | None = None  # low-pass cutoff [Hz]; None: no filtering
    order: int = 4  # Butterworth order (the paper: 4th order, 1 Hz)
    differentiate: bool = False  # recompute qd, qdd from q even when the file has them


@dataclass
class Signals:
    """What the models take: one conditioned recording."""

    name: str
    t: np.ndarray  # (T,)
    q: np.ndarray  # (T, N)
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray | None  # (T, N)
    extra: dict  # other columns (filtered like the torques)

    @property
    def rate(self) -> float:
        return 1.0 / float(np.median(np.diff(self.t)))


def condition(recording: Recording, options: Conditioning = Conditioning()) -> Signals:
    r = recording
    rate = 1.0 / float(np.median(np.diff(r.t)))
    lowpass = _lowpass(r.name, rate, options)
    q = lowpass(r.q)
    if r.qd is None or options.differentiate:
        qd = np.gradient(q, r.t, axis=0)  # second-order central differences (non-uniform t allowed)
        qdd = np.gradient(qd, r.t, axis=0)
    else:
        qd = lowpass(r.qd)
        qdd = lowpass(r.qdd) if r.qdd is not None else np.gradient(qd, r.t, axis=0)
    tau = lowpass(r.tau) if r.tau is not None else None
    extra = {k: lowpass(v) for k, v in r.extra.items()}
    return Signals(r.name, r.t, q, qd, qdd, tau, extra)


def _lowpass(name: str, rate: float, options: Conditioning):
    if options.cutoff is None:
        return lambda x: np.array(x, dtype=float)
    if not 0 < options.cutoff < rate / 2:
        raise InputError(name, "cutoff", f"{options.cutoff:g} Hz must lie between 0 and half the sampling rate "
                         f"({rate / 2:g} Hz)")
    if not 1 <= options.order <= 12:
        raise InputError(name, "order", f"{options.order} must be between 1 and 12")
    sos = signal.butter(options.order, options.cutoff, btype="low", fs=rate, output="sos")

    def apply(x):
        x = np.asarray(x, dtype=float)
        pad = min(x.shape[0] - 1, 3 * (2 * len(sos) + 1))
        return signal.sosfiltfilt(sos, x, axis=0, padlen=pad)

    return apply
