"""Stage 5, test: the figures on the judged data (the test recordings, or without them the
selection data): RMS before, after, with the effects alone and with the simple model, per
phase of the motion, the noise left, and within the speeds the fit data covered.

Of a long test recording diagnosed on windows (streaming/sample.py), the four mean squares are
over every row of it, read again in blocks (over_every_row); its peak, noise, phases and speed
shares stay those of its windows."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..terms import simple_model
from . import phases


@dataclass(frozen=True)
class Judged:
    """The judged data's figures (mean squares per joint; `where`: phases.by_phase with rms_after)."""

    on: str  # "test" or "selection"
    before: np.ndarray
    after: np.ndarray
    effects: np.ndarray
    simple: np.ndarray
    peak_before: np.ndarray
    noise: np.ndarray
    where: list
    within_fit_speeds: dict
    used: list  # the segments with judged samples


def judge(design, segments, chosen, final, simple) -> Judged:
    """The figures on the test samples, or on the selection samples where there are none; the
    segments' corrections are the final model's (joints.apply)."""
    on = "test" if design.test.count else "selection"
    moments = design.test if on == "test" else design.select
    before = moments.c / max(moments.count, 1)
    effects_mse = moments.mse(final.slots, final.x) if chosen else before.copy()
    simple_mse_ = simple_mse(segments, simple, "test" if on == "test" else "select", before.size)
    mask = (lambda seg: seg.test) if on == "test" else (lambda seg: seg.select)
    used = [seg for seg in segments if mask(seg).any()]
    held_before = np.vstack([seg.residual[mask(seg)] for seg in used])
    held_after = np.vstack([(seg.residual - seg.correction)[mask(seg)] for seg in used])
    after = np.mean(held_after ** 2, axis=0)
    masks = [phases.labels(*(getattr(seg.signals, k)[mask(seg)] for k in ("t", "q", "qd", "qdd"))) for seg in used]
    masks = {name: np.vstack([m[name] for m in masks]) for name in phases.PHASES}
    where = phases.by_phase(held_before, masks)
    for w, a in zip(where, phases.by_phase(held_after, masks)):
        w["rms_after"] = a["rms"]
        for name, v in w["phases"].items():
            v["rms_after"] = a["phases"][name]["rms"]
    noise = np.std(np.diff(held_after, axis=0), axis=0) / np.sqrt(2)
    return Judged(on, before, after, effects_mse, simple_mse_, np.abs(held_before).max(axis=0), noise, where,
                  within_fit_speeds(segments, simple, used, mask), used)


def held_sums(seg, effects, simple) -> tuple[np.ndarray, int]:
    """((4, N) sums of squares over the segment's test samples before, after its final
    correction, after the effects' torques (T, N) alone and after the simple model; their count)."""
    m = seg.test
    r = seg.residual[m]
    return np.array([((r - x) ** 2).sum(axis=0) for x in (0.0, seg.correction[m], effects[m],
                                                          simple_model.predict(simple, seg)[m])]), int(m.sum())


def over_every_row(judged: Judged, sums) -> Judged:
    """judged with its mean squares before, after, with the effects alone and with the simple
    model from `sums` (held_sums, one segment at a time: the in-memory test segments, and every
    row of the long test recordings block by block), added in order."""
    sse, count = 0.0, 0
    for part, rows in sums:
        sse, count = sse + part, count + rows
    before, after, effects, simple = sse / max(count, 1)
    return replace(judged, before=before, after=after, effects=effects, simple=simple)


def within_fit_speeds(segments, simple, used, mask) -> dict:
    """Per joint on the judged samples whose velocity lies within the range the fit samples
    covered: {"share_beyond": share of judged samples outside it, "rms_after", "rms_simple"
    (None where no sample is within)}. Beyond the fit speeds a velocity law is extrapolated, and
    the selection data, drawn from the fit recordings, cannot show how well."""
    qd = np.vstack([seg.signals.qd[seg.fit] for seg in segments if seg.fit.any()])
    lo, hi = qd.min(axis=0), qd.max(axis=0)
    out = {"share_beyond": [], "rms_after": [], "rms_simple": []}
    simple_torque = [simple_model.predict(simple, seg) for seg in used]
    for j in range(lo.size):
        sse_after = sse_simple = 0.0
        inside = total = 0
        for seg, tau_simple in zip(used, simple_torque):
            m = mask(seg)
            v = seg.signals.qd[m, j]
            k = (v >= lo[j]) & (v <= hi[j])
            r = seg.residual[m, j][k]
            sse_after += float(np.sum((r - seg.correction[m, j][k]) ** 2))
            sse_simple += float(np.sum((r - tau_simple[m, j][k]) ** 2))
            inside += int(k.sum())
            total += int(m.sum())
        out["share_beyond"].append(1.0 - inside / max(total, 1))
        out["rms_after"].append(float(np.sqrt(sse_after / inside)) if inside else None)
        out["rms_simple"].append(float(np.sqrt(sse_simple / inside)) if inside else None)
    return out


def simple_mse(segments, simple, role, n) -> np.ndarray:
    sse, count = np.zeros(n), 0
    for seg in segments:
        m = getattr(seg, role)
        if m.any():
            sse += ((seg.residual[m] - simple_model.predict(simple, seg)[m]) ** 2).sum(axis=0)
            count += int(m.sum())
    return sse / max(count, 1)
