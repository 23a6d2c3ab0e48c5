"""Per joint, the final model: the selected effects, the simple model, or both together.

The simple model (baseline.py) is what every diagnosis must beat. On each joint three models
are fitted on the fit samples and compared on the selection samples:

  effects    the selected effects as fitted together (the diagnosis's findings);
  simple     b + Fc tanh(qd/0.02) + Fv qd alone;
  completed  the effects acting on the joint plus those of the simple model's three columns that
             none of them already is (Effect.covers), refitted on that joint (the arm-wide
             effects' torque kept as it is): a joint whose effects were each chosen for a large
             gain may still lack an offset or a plain friction term that none of them covers.
             (Two viscous columns, one clipped to the fit velocities and one not, agree on the
             fit data and disagree wildly beyond it: hence no column twice.)

  consistent the link parameters re-identified, physically consistent, with their own friction
             (reidentify.py), where they were computed: counted as its per-joint values plus one
             (reidentify.JOINT_VALUES), and it must gain at least `min_gain` of the mean square
             over the best of the three others on the joint's selection data in any case.

The effects stay unless another model does better on the selection data, where the model with
more values on the joint must gain `min_gain` of the mean square per extra value (what an
effect must gain to be selected at all), so that three numbers fitting noise do not replace a
one-value finding, and six ripple harmonics do not displace the simple model on a whim. The decision is made with the values fitted on the fit samples only;
`apply` then sets each joint's correction with the final values.
"""

from __future__ import annotations

import numpy as np

from . import baseline
from . import design as dz

EFFECTS, SIMPLE, COMPLETED, CONSISTENT = "effects", "simple", "effects + simple", "consistent parameters"


def _split(chosen, x):
    out, offset = [], 0
    for c in chosen:
        out.append(x[offset: offset + c.size])
        offset += c.size
    return out


def _missing(chosen, j) -> list[int]:
    """The simple model's columns that no effect on joint j already is."""
    covered = {c.effect.covers for c in chosen if c.joint == j}
    return [k for k, name in enumerate(baseline.NAMES) if name not in covered]


def _parts(context, chosen, x, seg, j):
    """(arm-wide effects' torque on joint j, columns of the per-joint effects on joint j)."""
    arm = np.zeros(seg.residual.shape[0])
    columns = []
    for c, v in zip(chosen, _split(chosen, x)):
        cols = dz.columns_of(c.effect, context, seg)[:, j, :]
        if c.joint is None:
            arm += cols @ v
        elif c.joint == j:
            columns.append(cols)
    return arm, columns


def _completed_fit(context, chosen, x, segments, j):
    """Least squares of [per-joint effects on j, the simple model's missing columns] to the
    residual left by the arm-wide effects, on the fit samples. Friction must dissipate over the
    velocities the fit data cover: a negative Coulomb level, or a negative viscous slope that
    makes the joint's friction push at the fastest fit velocity, is dropped and the rest
    refitted (such values are no joint's, and they extrapolate worst; a friction that falls
    with speed but stays positive is a real joint's Stribeck curve). Returns (the simple
    columns kept, the values)."""
    extra = _missing(chosen, j)
    fastest = max(abs(context.qd_range[0][j]), abs(context.qd_range[1][j])) if context.qd_range else 0.0
    coulomb = [c for c in chosen if c.joint == j and c.effect.covers == "Fc"]
    while True:
        rows, targets = [], []
        for seg in segments:
            if not seg.fit.any():
                continue
            arm, columns = _parts(context, chosen, x, seg, j)
            rows.append(np.column_stack(columns + [baseline.columns(seg.signals)[:, j, extra]])[seg.fit])
            targets.append((seg.residual[:, j] - arm)[seg.fit])
        values = np.linalg.lstsq(np.vstack(rows), np.concatenate(targets), rcond=1e-10)[0]
        own = values.size - len(extra)
        named = {baseline.NAMES[k]: (k, v) for k, v in zip(extra, values[own:])}
        level = named["Fc"][1] if "Fc" in named else 0.0
        level += sum(v for c, v in zip(_joint_chosen(chosen, j), _own_values(chosen, j, values)) if c in coulomb)
        if "Fc" in named and named["Fc"][1] < 0:
            extra.remove(named["Fc"][0])
        elif "Fv" in named and level + named["Fv"][1] * fastest < 0:
            extra.remove(named["Fv"][0])
        else:
            return extra, values


def _joint_chosen(chosen, j) -> list:
    return [c for c in chosen if c.joint == j]


def _own_values(chosen, j, values) -> list[float]:
    """The first value of each per-joint effect on j, in the completed fit's values."""
    out, offset = [], 0
    for c in _joint_chosen(chosen, j):
        out.append(float(values[offset]))
        offset += c.size
    return out


def _completed_predict(context, chosen, x, completed, seg, j):
    extra, values = completed
    arm, columns = _parts(context, chosen, x, seg, j)
    return arm + np.column_stack(columns + [baseline.columns(seg.signals)[:, j, extra]]) @ values


def decide(context, segments, chosen, x, simple, min_gain: float, consistent=None, consistent_values: int = 0) \
        -> list[str]:
    """Per joint EFFECTS, SIMPLE, COMPLETED or (given consistent: per segment its corrections
    (T, N), with consistent_values values counted per joint) CONSISTENT; seg.correction holds
    the effects' torques."""
    n = segments[0].residual.shape[1]
    modes = []
    for j in range(n):
        acting = any(c.joint is None or c.joint == j for c in chosen)
        values = _completed_fit(context, chosen, x, segments, j) if acting else None
        acting = acting and bool(values[0])  # no simple column left to add: the same model as the effects
        sse = {EFFECTS: 0.0, SIMPLE: 0.0, COMPLETED: 0.0, CONSISTENT: 0.0}
        for i, seg in enumerate(segments):
            m = seg.select
            if not m.any():
                continue
            r = seg.residual[m, j]
            sse[EFFECTS] += float(np.sum((r - seg.correction[m, j]) ** 2))
            sse[SIMPLE] += float(np.sum((r - baseline.predict(simple, seg)[m, j]) ** 2))
            if acting:
                sse[COMPLETED] += float(np.sum((r - _completed_predict(context, chosen, x, values, seg, j)[m]) ** 2))
            if consistent is not None:
                sse[CONSISTENT] += float(np.sum((r - consistent[i][m, j]) ** 2))
        own = sum(c.size for c in chosen if c.joint == j)  # values of the effects on this joint
        size = {EFFECTS: own, SIMPLE: len(baseline.NAMES), COMPLETED: own + len(values[0]) if acting else 0}
        best = EFFECTS
        for other in (SIMPLE, COMPLETED) if acting else (SIMPLE,):
            if _better(sse[other], size[other], sse[best], size[best], min_gain):
                best = other
        if consistent is not None and _better(sse[CONSISTENT], consistent_values, sse[best], size[best], min_gain) \
                and sse[CONSISTENT] < (1 - min_gain) * sse[best]:
            best = CONSISTENT
        modes.append(best)
    return modes


def _better(sse, size, best_sse, best_size, min_gain) -> bool:
    """Whether a model beats the current best on selection data, the one with more values
    having to gain `min_gain` of the mean square per extra value (as an effect must to be
    selected), the one with fewer values winning ties."""
    if size > best_size:
        return sse < (1 - min_gain) ** (size - best_size) * best_sse
    return sse <= best_sse / (1 - min_gain) ** (best_size - size)


def apply(context, segments, chosen, x, simple, modes, consistent=None) -> dict:
    """Set seg.correction per joint by its mode (the effects' torques already there; consistent:
    per segment the consistent model's corrections); returns {joint (1-based): {column: value}
    of the completed model} for the report."""
    completed = {}
    for j, mode in enumerate(modes):
        if mode == CONSISTENT:
            for seg, c in zip(segments, consistent):
                seg.correction[:, j] = c[:, j]
        elif mode == SIMPLE:
            for seg in segments:
                seg.correction[:, j] = baseline.predict(simple, seg)[:, j]
        elif mode == COMPLETED:
            fitted = _completed_fit(context, chosen, x, segments, j)
            names = [f"{c.key}.{p}" for c in chosen if c.joint == j for p in c.effect.parameters]
            completed[j + 1] = dict(zip(names + [baseline.NAMES[k] for k in fitted[0]], fitted[1].tolist()))
            for seg in segments:
                seg.correction[:, j] = _completed_predict(context, chosen, x, fitted, seg, j)
    return completed
