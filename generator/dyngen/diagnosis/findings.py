"""Stage 6, report: each chosen effect as a finding (its gain and joints on the selection data,
its values and deviations, what follows from them), and the split of the findings into
those reported and those superseded on joints another model won."""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np

from .record import Finding
from .forward_selection import relative_change, selection_gain, selection_mse


def describe(design, chosen, cand, min_gain) -> Finding:
    """What an effect does on the selection data (its gain, the joints it helps); values come in with_values."""
    mse_without = selection_mse(design, [c for c in chosen if c is not cand])
    mse_with = selection_mse(design, chosen)
    gain_per_joint = relative_change(mse_without, mse_with)
    gain = selection_gain(cand, mse_without, mse_with)
    joints = [cand.joint + 1] if cand.joint is not None else \
        [j + 1 for j in range(len(gain_per_joint)) if gain_per_joint[j] >= min_gain]
    return Finding(effect=cand.effect.name, joints=tuple(joints), variant=cand.effect.fixed(), values={}, std={},
                   units=dict(zip(cand.effect.parameters, cand.effect.units)), derived={}, selection_gain=gain,
                   rms_before=np.sqrt(mse_without).tolist(), rms_after=np.sqrt(mse_with).tolist(),
                   suspect=cand.effect.suspect)


def with_values(described, design, chosen, final, tau_corr, robot) -> list[Finding]:
    """The findings with the final values, deviations scaled for the correlation time, and Term.derived."""
    offset, out = 0, []
    for cand, e in zip(chosen, described):
        k = slice(offset, offset + cand.size)
        offset += cand.size
        std = np.sqrt(np.maximum(np.diag(final.covariance)[k], 0.0) * tau_corr)
        determined = identifiable(design, chosen)[k]
        names = cand.effect.parameters
        values = {nm: (float(v) if ok else None) for nm, v, ok in zip(names, final.x[k], determined)}
        std = {nm: (float(d) if ok else None) for nm, d, ok in zip(names, std, determined)}
        derived = cand.effect.derived(robot, values, std, partial(_torque_rms, design, cand, final.x[k]))
        out.append(replace(e, values=values, std=std, variant=cand.effect.fixed(), derived=derived))
    return out


def _torque_rms(design, cand, x) -> float:
    """RMS torque of a per-joint candidate's values x on its joint over the fit samples."""
    G = design.fit.G[cand.joint][np.ix_(cand.slots, cand.slots)]
    return float(np.sqrt(max(x @ G @ x, 0.0) / max(design.fit.count, 1)))


def identifiable(design, chosen, most: float = 0.5) -> np.ndarray:
    """Per value of the chosen (in their order), whether the data determine it: less than `most`
    of it in the null space of the weighted normal matrix."""
    slots = np.concatenate([c.slots for c in chosen])
    H = design.H[np.ix_(slots, slots)]
    d = np.sqrt(np.maximum(np.diag(H), 1e-300))
    vals, vecs = np.linalg.eigh(H / np.outer(d, d))
    weak = vals <= 1e-10 * max(vals.max(), 1e-300)
    return (vecs[:, weak] ** 2).sum(axis=1) < most


def reported(chosen, described, replaced) -> tuple[list[Finding], list[Finding]]:
    """(selected, superseded on joints another model won); an arm-wide finding keeps the other joints."""
    selected, superseded = [], []
    for c, e in zip(chosen, described):
        if c.joint is not None and c.joint in replaced:
            superseded.append(e)
            continue
        selected.append(replace(e, joints=tuple(j for j in e.joints if j - 1 not in replaced)))
    return selected, superseded
