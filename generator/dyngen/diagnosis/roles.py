"""Three roles for data, never mixed: fit sets the values, select chooses the effects (never fitted
to them), test is used for nothing but the residual reported as held out. Without select
recordings, every third block of the fit recordings selects (each third in turn,
Segment.groups), with the filter's reach around each cut in neither role. `repeated` finds test
recordings that repeat a fit trajectory (evidence of repetition, not generalisation)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..catalogue import RNEA

REPEATED_SHARE = 0.02  # RMS position difference below this share of the motion's range: same trajectory


@dataclass(frozen=True)
class Segment:
    """One recording with the model's torques, its residual and its samples' roles (frozen)."""

    signals: object
    tau_model: np.ndarray
    residual: np.ndarray
    fit: np.ndarray  # bool (T,)
    select: np.ndarray
    test: np.ndarray
    correction: np.ndarray | None = None  # the final model's correction (effects, or the simple model per joint)
    groups: list | None = None  # bool (T,) per block group (selection on blocks): each cut selects on one


def segments(model, s, fit_signals, select_signals, test_signals, block_seconds: float) -> tuple[list, str]:
    out = []

    def segment(sig, fit, select, test, groups=None):
        # The filtered motion's torque is the filtered torque's model (filtering it again would smooth
        # twice what the recording smoothed once), unless the positions' noise is not the white noise the
        # cutoff was chosen for (Signals.model_filtered, automatic.coloured): then it is filtered alike.
        tau_model = model.batch(RNEA.name, sig.q, sig.qd, sig.qdd, s)
        tau_model = sig.filtered(tau_model) if sig.model_filtered else tau_model
        return Segment(sig, tau_model, sig.tau - tau_model, fit, select, test, groups=groups)

    none = lambda sig: np.zeros(sig.t.size, dtype=bool)  # noqa: E731
    if select_signals:
        out += [segment(sig, sig.inner(), none(sig), none(sig)) for sig in fit_signals]
        out += [segment(sig, none(sig), sig.inner(), none(sig)) for sig in select_signals]
        split = "selection on separate recordings"
    else:
        out += [segment(sig, *blocks(sig, block_seconds), none(sig),
                        [blocks(sig, block_seconds, phase)[1] for phase in range(FOLDS)]) for sig in fit_signals]
        split = f"selection on blocks of {block_seconds:g} s of the fit data (each third of them in turn)"
    out += [segment(sig, none(sig), none(sig), sig.inner()) for sig in test_signals or []]
    return out, split


FOLDS = 3  # every third block selects; the per-joint models are compared over all three (choose.py)


def blocks(sig, block_seconds: float, phase: int = FOLDS - 1) -> tuple[np.ndarray, np.ndarray]:
    """(fit, select) masks: blocks phase, phase + FOLDS, ... select, the filter's reach at cuts in neither."""
    inner = sig.inner()
    block = np.floor((sig.t - sig.t[0]) / block_seconds).astype(int)
    select = block % FOLDS == phase
    guard = max(sig.trim - 2, 0)  # the filter's reach in samples (conditioning.EDGE_PERIODS)
    if guard:
        edges = np.flatnonzero(np.diff(select.astype(int))) + 0.5
        k = np.arange(sig.t.size)
        near = np.zeros(sig.t.size, dtype=bool)
        for e in edges:
            near |= np.abs(k - e) <= guard
        inner = inner & ~near
    return inner & ~select, inner & select


def repeated(fit_signals, test_signals) -> list[tuple[str, str, float]]:
    """(fit name, test name, RMS position difference [rad]) for each test recording following a fit one."""
    out = []
    for test in test_signals or []:
        for fit in fit_signals:
            tf, tt = fit.t - fit.t[0], test.t - test.t[0]
            span = min(tf[-1], tt[-1])
            if span <= 0 or span < 0.5 * max(tf[-1], tt[-1]):
                continue
            k = tf <= span
            q_test = np.column_stack([np.interp(tf[k], tt, test.q[:, j]) for j in range(test.q.shape[1])])
            diff = float(np.sqrt(np.mean((fit.q[k] - q_test) ** 2)))
            motion = float(np.mean(np.ptp(fit.q, axis=0)))
            if motion > 0 and diff < REPEATED_SHARE * motion:
                out.append((fit.name, test.name, diff))
    return out
