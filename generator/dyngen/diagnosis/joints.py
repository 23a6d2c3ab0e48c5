"""Per joint, the final model, fitted on the fit samples and compared on the selection samples
(the rules and the cases behind them: docs/measured-data.md, "Never worse than the simple model"):

  effects    the selected effects as fitted together (the diagnosis's findings);
  simple     b + Fc tanh(qd/0.02) + Fv qd alone (terms/simple_model.py, what every diagnosis must beat);
  completed  the effects acting on the joint as fitted, plus the simple model's three columns
             fitted to what they leave on that joint (an offset or a plain friction term that
             none of the effects covers);
  consistent the re-identified, physically consistent link parameters (reidentify.py), where
             computed: counted as reidentify.JOINT_VALUES values, and gaining at least `min_gain`
             of the mean square over the best of the three others in any case.

A model with more values on the joint must gain `min_gain` of the mean square per extra value
(what an effect must gain to be selected), so that three numbers fitting noise do not replace a
one-value finding. That margin decides what is *claimed*; what *predicts* the joint's torque is
the simple model unless the model chosen beats it by `min_gain` (else TIED: the effects stay
findings, and where the data cannot tell the two apart, the baseline is the one used). `apply`
then sets each joint's correction with the final values.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..terms import simple_model as baseline
from . import moments as dz

EFFECTS, SIMPLE, COMPLETED, CONSISTENT = "effects", "simple", "effects + simple", "consistent parameters"
TIED = "simple (effects not shown better)"  # the simple model predicts; the effects stay findings
# Least gain per extra value on errors summed over the three cuts of the fit recordings
# (choose.on_folds): every fit sample is judged once, so the sums are far less noisy than one
# selection set's. Values that fit noise change a held-out error by about 2 sqrt(k) / N_eff of it
# (N_eff: independent samples, a few hundred in 25 s at 200 Hz): 2 % per value is several times that.
FOLDS_PER_VALUE = 0.02


def _parts(context, chosen, x, seg, j):
    """(arm-wide effects' torque on joint j, columns of the per-joint effects on joint j)."""
    context = dz.as_chosen(context, chosen)
    arm = np.zeros(seg.residual.shape[0])
    columns = []
    for c, v in zip(chosen, dz.split_values(chosen, x)):
        cols = dz.columns_of(c.effect, context, seg)[:, j, :]
        if c.joint is None:
            arm += cols @ v
        elif c.joint == j:
            columns.append(cols)
    return arm, columns


def _completed_fit(context, chosen, x, segments, j):
    """Values of [per-joint effects on j, simple columns]: the effects' as fitted (x), the
    simple columns' by least squares to what all the effects leave on joint j, on the fit
    samples. (Refitting the effects with the simple columns let an offset and a position
    ripple's low harmonics, nearly collinear over a short range, take large values of
    opposite sign.)"""
    own = [v for c, v in zip(chosen, dz.split_values(chosen, x)) if c.joint == j]
    own = np.concatenate(own) if own else np.zeros(0)
    rows, targets = [], []
    for seg in segments:
        if not seg.fit.any():
            continue
        arm, columns = _parts(context, chosen, x, seg, j)
        effects = np.column_stack(columns) @ own if columns else 0.0
        rows.append(baseline.columns(seg.signals)[seg.fit, j, :])
        targets.append((seg.residual[:, j] - arm - effects)[seg.fit])
    return np.concatenate([own, np.linalg.lstsq(np.vstack(rows), np.concatenate(targets), rcond=1e-10)[0]])


def _completed_predict(context, chosen, x, values, seg, j):
    arm, columns = _parts(context, chosen, x, seg, j)
    return arm + np.column_stack(columns + [baseline.columns(seg.signals)[:, j, :]]) @ values


def decide(context, segments, chosen, x, simple, min_gain: float, consistent=None, consistent_values: int = 0) \
        -> list[str]:
    """Per joint EFFECTS, SIMPLE, TIED, COMPLETED or (given consistent: per segment its corrections
    (T, N), with consistent_values values counted per joint) CONSISTENT; seg.correction holds
    the effects' torques."""
    return choose(errors(context, segments, chosen, x, simple, consistent), chosen, min_gain, consistent_values)


def errors(context, segments, chosen, x, simple, consistent=None) -> list[dict]:
    """Per joint {model: sum of squared residuals on the selection samples}, every model
    fitted on the fit samples (seg.correction holds the effects' torques at values x)."""
    out = []
    for j in range(segments[0].residual.shape[1]):
        acting = any(c.joint is None or c.joint == j for c in chosen)
        values = _completed_fit(context, chosen, x, segments, j) if acting else None
        sse = dict.fromkeys([EFFECTS, SIMPLE] + [COMPLETED] * acting + [CONSISTENT] * (consistent is not None), 0.0)
        for i, seg in enumerate(segments):
            m = seg.select
            if not m.any():
                continue
            predicted = {EFFECTS: seg.correction[m, j], SIMPLE: baseline.predict(simple, seg)[m, j]}
            if acting:
                predicted[COMPLETED] = _completed_predict(context, chosen, x, values, seg, j)[m]
            if consistent is not None:
                predicted[CONSISTENT] = consistent[i][m, j]
            for model, torque in predicted.items():
                sse[model] += float(np.sum((seg.residual[m, j] - torque) ** 2))
        out.append(sse)
    return out


def choose(sse_per_joint: list[dict], chosen, min_gain: float, consistent_values: int = 0) -> list[str]:
    """The model per joint from its selection errors (errors(), or their sums over folds)."""
    modes = []
    for j, sse in enumerate(sse_per_joint):
        own = sum(c.size for c in chosen if c.joint == j)  # values of the effects on this joint
        # the completed model's independent values: an offset or viscous effect is a simple term
        shared = sum(1 for c in chosen if c.joint == j and c.effect.simple_term)
        size = {EFFECTS: own, SIMPLE: len(baseline.NAMES), COMPLETED: own + len(baseline.NAMES) - shared}
        best = EFFECTS
        for other in (SIMPLE, COMPLETED) if COMPLETED in sse else (SIMPLE,):
            if _better(sse[other], size[other], sse[best], size[best], min_gain):
                best = other
        if CONSISTENT in sse and _better(sse[CONSISTENT], consistent_values, sse[best], size[best], min_gain) \
                and sse[CONSISTENT] < (1 - min_gain) * sse[best]:
            best = CONSISTENT
        # (COMPLETED is there where an effect acts; a joint no effect acts on keeps the nominal model
        # unless the simple model wins outright)
        if COMPLETED in sse and best in (EFFECTS, COMPLETED) and not sse[best] < (1 - min_gain) * sse[SIMPLE]:
            best = TIED
        modes.append(best)
    return modes


def _better(sse, size, best_sse, best_size, min_gain) -> bool:
    """Whether a model beats the current best on selection data by the rule above (fewer values win ties)."""
    if size > best_size:
        return sse < (1 - min_gain) ** (size - best_size) * best_sse
    return sse <= best_sse / (1 - min_gain) ** (best_size - size)


def apply(context, segments, chosen, x, simple, modes, consistent=None, completed_values=None) -> tuple[list, dict]:
    """(segments with each joint's correction by its mode, {joint (1-based): values of the
    completed model} for the report). The segments' corrections hold the effects' torques;
    consistent: per segment the consistent model's corrections; completed_values: the completed
    model's values as apply returned them on the fit segments (blocks of a test recording have
    no fit samples to set them)."""
    completed, corrections = {}, [seg.correction.copy() for seg in segments]
    for j, mode in enumerate(modes):
        if mode == CONSISTENT:
            for out, c in zip(corrections, consistent):
                out[:, j] = c[:, j]
        elif mode in (SIMPLE, TIED):
            for out, seg in zip(corrections, segments):
                out[:, j] = baseline.predict(simple, seg)[:, j]
        elif mode == COMPLETED:
            values = _completed_fit(context, chosen, x, segments, j) if completed_values is None else \
                np.asarray(completed_values[j + 1])
            completed[j + 1] = values.tolist()
            for out, seg in zip(corrections, segments):
                out[:, j] = _completed_predict(context, chosen, x, values, seg, j)
    return [dataclasses.replace(seg, correction=c) for seg, c in zip(segments, corrections)], completed
