"""Signal conditioning: what the models take from a recording. Recorded qd, qdd are used as they are,
else q is differentiated through a zero-phase Butterworth low-pass (cutoff from automatic.py, or
given) kept as Signals.lowpass for everything compared with the torque; `trim` samples at each end
are its start-up. Rows as a logger wrote them are made one regular clock's first (log_quality.py)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy import signal

from ..arguments import real
from ..errors import InputError
from ..options import option
from . import automatic, log_quality
from .recording import Recording

AUTO = "auto"
EDGE_PERIODS = 1.0  # trimmed at each end: this many periods of the cutoff (the filter's start-up)
PAD_PERIODS = 2.0  # the recording is continued this many periods of the cutoff before filtering
VELOCITY_AGREES = (0.8, 1.25)  # recorded qd / the positions' derivative; beyond: another unit, sign or gear side
VELOCITY_EXPLAINED = 0.3  # ... when that factor leaves at most this share of the recorded qd's RMS
MIN_DATA = 16  # samples of data that long gaps in the stamps must leave (Signals.in_gaps)


def cutoff_of(text: str):
    """A cutoff in Hz, or AUTO (chosen from each recording) or None ("none": no filter)."""
    if text in (AUTO, "none"):
        return None if text == "none" else AUTO
    return real(0, 1e6, above=True)(text)


@dataclass(frozen=True)
class Conditioning:

    cutoff: float | str | None = option(
        AUTO, "override: zero-phase Butterworth low-pass on positions and torques alike, in Hz, or 'none'. "
        "auto: recorded qd, qdd are used as they are; otherwise q is differentiated through a cutoff chosen from "
        "the recording (its position noise against the motion's acceleration), and the choice is reported",
        metavar="HZ", parse=cutoff_of)
    order: int = option(4, "Butterworth order", metavar="N", bounds=(1, 12))
    differentiate: bool = option(False, "compute qd, qdd from q even when the file has them")


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
    lowpass: Callable | None = None  # the filter applied to q and tau (None: none)
    trim: int = 0  # samples at each end that are filter start-up, not data
    cutoff: float | None = None
    note: str = "as recorded"  # what was done, in words (for reports)
    q_noise: np.ndarray | None = None  # per joint position noise sigma [rad], when differentiated
    qdd_noise: np.ndarray | None = None  # per joint acceleration noise left after the filter [rad/s^2]
    band: float | None = None  # Hz: the motion's band (99 % of velocity power)
    warnings: list = field(default_factory=list)
    log: object = None  # log_quality.LogReport: what was done to the rows and stamps as written
    source: object = None  # the Recording as read and the Conditioning used (to condition it again)
    options: object = None
    model_filtered: bool = False  # the models' torques pass through lowpass too (automatic.coloured)

    @property
    def rate(self) -> float:
        return 1.0 / float(np.median(np.diff(self.t)))

    def filtered(self, x: np.ndarray) -> np.ndarray:
        """x (T, ...) through the same filter as the torques (unchanged if there is none)."""
        if self.lowpass is None:
            return np.asarray(x, dtype=float)
        shape = x.shape
        return self.lowpass(np.asarray(x, dtype=float).reshape(shape[0], -1)).reshape(shape)

    def of_joint(self, j: int) -> "Signals":
        """The signals of joint j alone, filtered the same way."""
        one = slice(j, j + 1)
        return dataclasses.replace(self, q=self.q[:, one], qd=self.qd[:, one], qdd=self.qdd[:, one],
                                   tau=None if self.tau is None else self.tau[:, one], extra={})

    def inner(self) -> np.ndarray:
        """Boolean (T,): the samples that are data (not the filter's start-up, nor in_gaps)."""
        keep = ~self.in_gaps()
        if self.trim:
            keep[:self.trim] = keep[-self.trim:] = False
        return keep

    def in_gaps(self) -> np.ndarray:
        """Boolean (T,): the samples interpolated in a long gap of the stamps (log_quality.LogReport.gaps),
        and `trim` samples either side (the filter's reach, as at the ends): made for the filter only."""
        return _in_gaps(self.t, getattr(self.log, "gaps", ()), self.trim)


def _in_gaps(t: np.ndarray, gaps, reach: int) -> np.ndarray:
    """Boolean (T,): samples strictly inside each (start, end) of gaps, and `reach` samples either side."""
    out = np.zeros(t.size, dtype=bool)
    for a, b in gaps:
        first, end = np.searchsorted(t, a, side="right"), np.searchsorted(t, b, side="left")
        out[max(first - reach, 0):end + reach] = True
    return out


def condition(recording: Recording, options: Conditioning = Conditioning()) -> Signals:
    differentiate = recording.qd is None or options.differentiate
    filtering = options.cutoff is not None and (options.cutoff != AUTO or differentiate or recording.qdd is None)
    # repeats, held columns, jittered stamps; uneven ones made a regular grid where a filter follows
    r, log = log_quality.regular_samples(recording, regrid=filtering)
    rate = 1.0 / float(np.median(np.diff(r.t)))
    disagrees = None if differentiate else _velocity_disagrees(r, rate)
    if disagrees:  # recorded qd in another unit or sign than q: the positions are differentiated instead
        out = condition(recording, dataclasses.replace(options, differentiate=True))
        out.warnings.insert(0, f"{r.name}: {disagrees}: qd, qdd differentiated from q instead")
        out.note = f"recorded qd set aside ({disagrees}); {out.note}"
        return out
    decision, cutoff = None, options.cutoff
    if isinstance(cutoff, str):
        if cutoff != AUTO:
            raise InputError(r.name, "cutoff", f"{cutoff!r}: expected a frequency in Hz or {AUTO!r}")
        if differentiate or r.qdd is None:  # q differentiated twice, or recorded qd once: a cutoff from its noise
            decision = automatic.decide(r.t, r.q if differentiate else r.qd,
                                        lambda fc: _lowpass(r.name, rate, fc, options.order), 2 if differentiate else 1,
                                        ~_in_gaps(r.t, log.gaps, 0) if log.gaps else None)
            cutoff = decision.cutoff
        else:
            cutoff = None  # the recording's own velocities: nothing to differentiate, nothing to filter
    lowpass = _lowpass(r.name, rate, cutoff, options.order) if cutoff is not None else None
    same = lowpass or (lambda x: np.array(x, dtype=float))
    q = same(r.q)  # qd, qdd where not recorded: second-order central differences (non-uniform t allowed)
    qd = np.gradient(q, r.t, axis=0) if differentiate else same(r.qd)
    qdd = np.gradient(qd, r.t, axis=0) if differentiate or r.qdd is None else same(r.qdd)
    tau = same(r.tau) if r.tau is not None else None
    extra = {k: same(v) for k, v in r.extra.items()}
    trim = 0
    if cutoff is not None:
        trim = int(np.ceil(EDGE_PERIODS * rate / cutoff)) + 2
    elif differentiate:
        trim = 2  # one-sided differences at the ends
    trim = min(trim, max((r.t.size - 4) // 4, 0))
    out = Signals(r.name, r.t, q, qd, qdd, tau, extra, lowpass, trim, cutoff, _note(differentiate, cutoff, options,
                                                                                      decision, r.qdd is None))
    if log.clock:
        out.note = f"{log.clock}; {out.note}"
        out.warnings.append(f"{r.name}: {log.clock}")
    if log.notes:
        out.note = "; ".join(log.notes) + f"; {out.note}"
        out.warnings.extend(log.warnings)
    for a, b in log.gaps:
        out.warnings.append(f"{r.name}: a gap of {b - a:.3g} s in the stamps ({(b - a) * rate:.0f} steps, at "
                            f"{a - r.t[0]:.4g} s): interpolated for the filter only; those samples and "
                            f"{trim / rate:.2g} s either side are not used as data")
    out.log, out.source, out.options = log, recording, options
    if log.gaps and np.count_nonzero(out.inner()) < MIN_DATA:
        raise InputError(r.name, "column t", f"{len(log.gaps)} long gap(s) in the stamps (up to {log.longest_gap:.3g} s) "
                         f"leave {np.count_nonzero(out.inner())} samples of data, fewer than {MIN_DATA}: the samples "
                         "interpolated in a gap, and the filter's reach around it, are not data")
    if decision is not None:
        out.q_noise, out.qdd_noise, out.band = decision.q_noise, decision.qdd_noise, decision.band
        out.model_filtered = cutoff is not None and automatic.coloured(r.q if differentiate else r.qd, rate, cutoff,
                                                                       decision.q_noise)
        if cutoff is not None and decision.band > 0 and cutoff < 2 * decision.band:
            out.warnings.append(f"{r.name}: {'position' if differentiate else 'velocity'} noise ({_sigma(decision.q_noise)})"
                                f" allows a cutoff of only {cutoff:.3g} Hz, below twice the motion's band "
                                f"({decision.band:.3g} Hz): accelerations are smoothed")
    elif differentiate:  # without a filter: the central second difference of white noise
        out.q_noise = sigma = automatic.position_noise(r.q)
        out.qdd_noise = automatic.acceleration_noise(sigma, cutoff, rate) if cutoff else sigma * np.sqrt(6.0) * rate ** 2
    return out


def _sigma(x) -> str:
    return f"{float(np.max(x)):.2g} rad"


def _note(differentiate, cutoff, options, decision, no_qdd) -> str:
    how = "qd, qdd differentiated from q" if differentiate else \
        ("qd as recorded, qdd differentiated" if no_qdd else "qd, qdd as recorded")
    if cutoff is None:
        return how + ", no filter"
    text = f"{how}; zero-phase Butterworth order {options.order}, {cutoff:.3g} Hz on q and tau"
    if decision is not None:
        noise = f"position noise {_sigma(decision.q_noise)}" if differentiate else \
            f"velocity noise {_sigma(decision.q_noise)}/s"
        text += f" (chosen from the data: {noise}, motion band {decision.band:.3g} Hz)"
    return text


def _velocity_disagrees(r: Recording, rate: float) -> str | None:
    """In words, the joints whose recorded qd is their positions' derivative times a factor outside
    VELOCITY_AGREES (deg/s beside rad gives 57.3, a motor-side velocity the gear ratio, -1 a sign),
    compared through one low-pass well above the motion and below the noise (a tenth of Nyquist,
    at most 10 Hz), on joints that move (over 1 % of the fastest); None where they agree."""
    if r.qd is None or r.t.size < 64:
        return None
    smooth = _lowpass(r.name, rate, min(0.05 * rate, 10.0), 2)
    edge = min(int(np.ceil(rate / 5.0)), r.t.size // 4)  # the filter's start-up at each end
    recorded = smooth(r.qd)[edge:-edge]
    derived = np.gradient(smooth(r.q), r.t, axis=0)[edge:-edge]
    size = np.sqrt(np.mean(derived ** 2, axis=0))
    factor = np.sum(recorded * derived, axis=0) / np.maximum(np.sum(derived ** 2, axis=0), 1e-300)
    left = np.sqrt(np.mean((recorded - factor * derived) ** 2, axis=0))
    lo, hi = VELOCITY_AGREES
    bad = [j for j in range(factor.size) if size[j] > 0.01 * size.max() and not lo <= factor[j] <= hi
           and left[j] <= VELOCITY_EXPLAINED * np.sqrt(np.mean(recorded[:, j] ** 2))]
    if not bad:
        return None
    return "recorded qd is " + ", ".join(f"{factor[j]:.3g} x the positions' derivative on joint {j + 1}"
                                         for j in bad) + " (deg/s gives 57.3, a motor-side velocity the gear ratio)"


def _lowpass(name: str, rate: float, cutoff: float, order: int):
    if not 0 < cutoff < rate / 2:
        raise InputError(name, "cutoff", f"{cutoff:g} Hz must lie between 0 and half the sampling rate "
                         f"({rate / 2:g} Hz)")
    sos = signal.butter(order, cutoff, btype="low", fs=rate, output="sos")
    reach = int(np.ceil(PAD_PERIODS * rate / cutoff))

    def apply(x):
        x = np.asarray(x, dtype=float)
        T = x.shape[0]
        pad = min(reach, T - 1)
        if pad < 8:
            return signal.sosfiltfilt(sos, x, axis=0, padlen=min(T - 1, 3 * (2 * len(sos) + 1)))
        # A recording rarely starts or ends at rest: continued by a quadratic in time (value,
        # slope and curvature continuous), the filter's start-up does not bend the second
        # derivative the way scipy's odd extension would (its curvature flips at the edge).
        head = _continued(x[:pad][::-1], pad)[::-1]
        tail = _continued(x[-pad:], pad)
        # filtered along the last axis of a contiguous copy: several times faster than along axis 0
        extended = np.ascontiguousarray(np.concatenate([head, x, tail]).reshape(T + 2 * pad, -1).T)
        out = signal.sosfiltfilt(sos, extended, axis=-1, padlen=0)[:, pad:pad + T]
        return np.ascontiguousarray(out.T).reshape(x.shape)

    apply.rate = rate  # what it was designed for (samples decimated later need another)
    return apply


def _continued(y: np.ndarray, n: int) -> np.ndarray:
    """n samples after y (time along axis 0), from a quadratic fitted to y."""
    coefficients = np.polyfit(np.arange(y.shape[0], dtype=float), y.reshape(y.shape[0], -1), 2)
    ahead = np.arange(y.shape[0], y.shape[0] + n, dtype=float)
    return (np.vander(ahead, 3) @ coefficients).reshape((n,) + y.shape[1:])
