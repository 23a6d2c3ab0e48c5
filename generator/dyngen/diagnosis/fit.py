"""Stage 1, fit: the moments of every candidate effect on every role's samples (moments.py),
weighted per joint, and the chosen candidates' torques on a segment at fitted values."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..data.correlation import integrated_time
from ..terms.context import Memo
from . import moments as dz
from . import roles


@dataclass
class CandidateMoments:
    """Every candidate's moments on each role's samples, weighted per joint (the diagnosis's design)."""
    candidates: list
    fit: dz.Moments
    select: dz.Moments
    test: dz.Moments
    weights: np.ndarray  # per joint: 1 / RMS of the nominal fit residual
    groups: list = field(default_factory=list)  # dz.Moments per block group (selection on blocks)
    H: np.ndarray = None  # weighted normal matrix of every slot: sum_j w_j^2 G_j (fit samples)
    g: np.ndarray = None  # sum_j w_j^2 b_j

    def __post_init__(self):
        w2 = self.weights ** 2
        self.H = np.einsum("j,jkl->kl", w2, self.fit.G)
        self.g = w2 @ self.fit.b


def build(context, effects, segments, n) -> CandidateMoments:
    candidates, moments = None, None
    for seg in segments:
        columns = dz.effect_columns(effects, context, seg)
        if candidates is None:
            candidates = dz.candidates_of(effects, n, {k: v.shape[2] for k, v in columns.items()})
            size = candidates[-1].start + candidates[-1].size
            moments = [dz.empty(n, size) for _ in range(3)]
            groups = [dz.empty(n, size) for _ in range(roles.FOLDS)]
        dz.add_segment([*zip(moments, (seg.fit, seg.select, seg.test)), *zip(groups, seg.groups or [])],
                      candidates, columns, seg)
    if moments[0].count == 0:
        raise ValueError("no fit samples (recordings too short for the filter's start-up?)")
    rms = np.sqrt(moments[0].c / max(moments[0].count, 1))
    weights = 1.0 / np.maximum(rms, 1e-9 * max(rms.max(), 1e-300))
    return CandidateMoments(candidates, *moments, weights, groups if any(m.count for m in groups) else [])


def predict(context, chosen, x, segment) -> np.ndarray:
    """The chosen candidates' torques (T, N) on one segment, for fitted values x (in chosen order)."""
    effects = list({c.effect.key: c.effect for c in chosen}.values())
    columns = dz.effect_columns(effects, dz.as_chosen(context, chosen), segment)
    out = np.zeros_like(segment.residual)
    for c, values in zip(chosen, dz.split_values(chosen, x)):
        block = columns[c.effect.key] @ values  # (T, N)
        if c.joint is None:
            out += block
        else:
            out[:, c.joint] += block[:, c.joint]
    return out


def corrected(context, chosen, x, segments) -> list:
    """The segments with their correction: the chosen candidates' torques at values x (zero without)."""
    return [dataclasses.replace(seg, correction=predict(context, chosen, x, seg) if chosen else
                                np.zeros_like(seg.residual)) for seg in segments]


def reweighted(design, final) -> CandidateMoments:
    """The design with each joint weighted by 1 / the RMS its residual keeps after the chosen effects:
    the nominal residual holds the very effects sought (a payload's 9 Nm on joint 2 would weigh it
    down as if it were noise)."""
    rms = np.sqrt(design.fit.mse(final.slots, final.x))
    return dataclasses.replace(design, weights=1.0 / np.maximum(rms, 1e-9 * max(rms.max(), 1e-300)))  # H, g anew


def correlation_time(segments, weights) -> float:
    """Integrated autocorrelation time of the final weighted fit residual, median over joints."""
    times = [integrated_time(w * np.concatenate([(seg.residual - seg.correction)[seg.fit, j] for seg in segments]))
             for j, w in enumerate(weights)]
    return float(np.median(times))


def positions(segments) -> tuple:
    """(low, high) per joint: the positions the fit samples cover (Context.q_range)."""
    q = np.vstack([seg.signals.q[seg.fit] for seg in segments if seg.fit.any()])
    return q.min(axis=0), q.max(axis=0)


def ranged(context, segments, chosen):
    """The context with the positions the fit samples cover if a chosen effect needs them."""
    return dataclasses.replace(context, q_range=positions(segments), cache=Memo()) \
        if any(c.effect.ranged for c in chosen) else context
