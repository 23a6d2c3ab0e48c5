"""The identification's columns beside the rigid body's base regressor. A label is (kind, j): per
joint j, in its rows only, coulomb tanh(qd_j(t - lag_j) / vs_j) (switching: through the
recording's filter, like the torque), viscous qd_j, offset 1, armature qdd_j, and the optional
group "ripple" cos q_j, sin q_j; for the arm the optional group "tilt", j its direction u1, u2
(terms/tilt.py), in every joint's rows. Each kind is a term of terms/ (TERM_OF)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from ..terms import joint_columns
from ..terms.friction import coulomb
from ..terms.joint_columns import TERM_OF

PER_JOINT = tuple(TERM_OF)
GROUPS = {"ripple": ("ripple_cos", "ripple_sin"), "tilt": ("tilt",)}  # optional groups and their kinds
# kinds whose value is held >= 0 (see consistent.py): the terms whose range is the positive values
BOUNDED = tuple(k for k in PER_JOINT if TERM_OF[k].values[0].low == 0.0)


def kinds_of(names) -> tuple:
    """Column kinds of user names: "ripple" stands for cos q_j and sin q_j."""
    wanted = set(names)
    wanted |= {k for group, kinds in GROUPS.items() if group in wanted for k in kinds}
    return tuple(k for k in PER_JOINT if k in wanted)


def group_of(label) -> str | None:
    return next((g for g, kinds in GROUPS.items() if label[0] in kinds), None)


def name_of(label) -> str:
    kind, j = label
    return f"tilt dg{j + 1}" if kind == "tilt" else f"{kind} j{j + 1}"  # dg1, dg2: along u1, u2 (terms/tilt.py)


def lagged(t, x, lag: float) -> np.ndarray:
    """x(t - lag), held at x(t_0) before the start."""
    return x if lag <= 0 else np.interp(t - lag, t, x)


def switching_filter(signals):
    """The recording's low-pass, for columns switching with the velocity's sign (redesigned if decimated)."""
    lowpass, cutoff = getattr(signals, "lowpass", None), getattr(signals, "cutoff", None)
    if lowpass is None or cutoff is None or len(signals.t) < 16:
        return lambda x: x
    rate, designed = signals.rate, getattr(lowpass, "rate", None)
    if designed is None or abs(designed - rate) <= 1e-3 * rate:
        return signals.filtered
    if not cutoff < 0.45 * rate:
        return lambda x: x
    sos = signal.butter(4, cutoff, btype="low", fs=rate, output="sos")
    return lambda x: signal.sosfiltfilt(sos, x, axis=0)


def coulomb_matrix(signals, smoothing, lags) -> np.ndarray:
    """(T, N): tanh(qd_j(t - lag_j) / vs_j), through the recording's filter."""
    qd = signals.qd
    lags = np.zeros(qd.shape[1]) if lags is None else lags
    raw = np.column_stack([coulomb(lagged(signals.t, qd[:, j], lags[j]), smoothing[j]) for j in range(qd.shape[1])])
    return switching_filter(signals)(raw)


def joint_column(signals, kind: str, j: int, coulomb=None) -> np.ndarray:
    """(T,): the column of (kind, j) in joint j's rows (coulomb from coulomb_matrix)."""
    return coulomb[:, j] if kind == "coulomb" else joint_columns.column(kind, signals.q[:, j], signals.qd[:, j],
                                                                          signals.qdd[:, j])


@dataclass
class Piece:
    """A block of one recording as the fit sees it (blocks.py): data samples, regressor and part of each sample."""

    signals: object  # the block's samples: t, q, qd, qdd, tau
    keep: slice  # the data samples among them
    Yj: np.ndarray  # (N, T, r) base regressor at the kept samples, joint by joint
    tau: np.ndarray  # (T, N)
    part: np.ndarray  # (T,) fold index
    columns: dict  # label -> (T,) for a joint's label (its rows), (T, N) for an arm label

    def column(self, label, coulomb_full=None, tilt=None) -> np.ndarray:
        kind, j = label
        return tilt[..., j] if kind == "tilt" else joint_column(self.signals, kind, j, coulomb_full)[self.keep]
