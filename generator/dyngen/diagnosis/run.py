"""The diagnosis: residual, forward selection of effects on held-out data, refinement of
their nonlinear settings, final fit.

    result = diagnose(robot, model, p, fit_signals, holdout_signals)   # or holdout None: blocks
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..catalogue import RNEA
from . import design as dz
from . import phases
from .correlation import integrated_time
from .effects import Context, library
from .refine import refine
from .selection import ALPHA, MIN_GAIN, forward, heldout_gain, prune, solve


@dataclass(frozen=True)
class Options:
    effects: tuple | None = None  # effect names to try (default: all)
    min_gain: float = MIN_GAIN
    alpha: float = ALPHA
    sign_velocity: float = 0.002  # rad/s: tanh smoothing of sign(qd)
    block_seconds: float = 2.0  # without held-out files: blocks of this length, every third held out


@dataclass
class Segment:
    """One recording with the model's torques, its residual and which samples fit / test."""

    signals: object
    tau_model: np.ndarray
    residual: np.ndarray
    fit: np.ndarray  # bool (T,)
    held: np.ndarray  # bool (T,)
    correction: np.ndarray | None = None  # the selected effects' torques, after the diagnosis


@dataclass
class Diagnosis:
    robot: str
    joints: int
    split: str  # "held-out recordings" or "blocks"
    selected: list  # per chosen candidate: dict (see docs/conventions.md, diagnosis JSON)
    rms_before: list  # per joint, held-out, nominal model
    rms_after: list  # per joint, held-out, with every selected effect
    peak_before: list
    noise_rms: list  # per joint estimate of the white part of the final held-out residual
    where: list  # per joint: phases of the nominal held-out residual (phases.by_phase), with rms_after
    candidates: list  # every candidate: its held-out gain when tried alone
    steps: list
    dropped: list  # selected forward, then dropped as not significant (correlated residual)
    correlation_samples: float  # integrated autocorrelation time used to scale the deviations
    segments: list = field(default_factory=list)  # Segment, for figures


def _segments(model, s, fit_signals, holdout_signals, options) -> tuple[list, str]:
    out = []

    def segment(sig, fit, held):
        tau_model = model.batch(RNEA.name, sig.q, sig.qd, sig.qdd, s)
        return Segment(sig, tau_model, sig.tau - tau_model, fit, held)

    if holdout_signals:
        for sig in fit_signals:
            out.append(segment(sig, np.ones(sig.t.size, bool), np.zeros(sig.t.size, bool)))
        for sig in holdout_signals:
            out.append(segment(sig, np.zeros(sig.t.size, bool), np.ones(sig.t.size, bool)))
        return out, "held-out recordings"
    for sig in fit_signals:
        block = np.floor((sig.t - sig.t[0]) / options.block_seconds).astype(int)
        held = block % 3 == 2
        out.append(segment(sig, ~held, held))
    return out, f"blocks of {options.block_seconds:g} s, every third held out"


@dataclass
class Design:
    candidates: list
    fit: dz.Moments
    held: dz.Moments
    weights: np.ndarray  # per joint: 1 / RMS of the nominal fit residual
    H: np.ndarray = None  # weighted normal matrix of every slot: sum_j w_j^2 G_j (fit samples)
    g: np.ndarray = None  # sum_j w_j^2 b_j

    def __post_init__(self):
        w2 = self.weights ** 2
        self.H = np.einsum("j,jkl->kl", w2, self.fit.G)
        self.g = w2 @ self.fit.b


def _design(context, effects, segments, n) -> Design:
    candidates, fit, held = None, None, None
    for seg in segments:
        columns = dz.effect_columns(effects, context, seg)
        if candidates is None:
            candidates = dz.candidates_of(effects, n, {k: v.shape[2] for k, v in columns.items()})
            size = candidates[-1].start + candidates[-1].size
            fit, held = dz.empty(n, size), dz.empty(n, size)
        for j in range(n):
            A, slots = dz.joint_matrix(candidates, columns, j)
            for moments, mask in ((fit, seg.fit), (held, seg.held)):
                if mask.any():
                    dz.accumulate(moments, A[mask], slots, seg.residual[mask, j], j)
        fit.count += int(seg.fit.sum())
        held.count += int(seg.held.sum())
    rms = np.sqrt(fit.c / max(fit.count, 1))
    weights = 1.0 / np.maximum(rms, 1e-9 * max(rms.max(), 1e-300))
    return Design(candidates, fit, held, weights)


def predict(context, chosen, x, segment) -> np.ndarray:
    """The chosen candidates' torques (T, N) on one segment, for fitted values x (in chosen order)."""
    effects = list({c.effect.key: c.effect for c in chosen}.values())
    columns = dz.effect_columns(effects, context, segment)
    out = np.zeros_like(segment.residual)
    offset = 0
    for c in chosen:
        values = x[offset: offset + c.size]
        block = columns[c.effect.key] @ values  # (T, N)
        if c.joint is None:
            out += block
        else:
            out[:, c.joint] += block[:, c.joint]
        offset += c.size
    return out


def diagnose(robot, model, p, fit_signals, holdout_signals=None, options: Options = Options()) -> Diagnosis:
    p = np.asarray(p, dtype=float)
    s = model("standard_from_dynamic", p)
    n = robot.dof
    context = Context(model, robot, p, s, options.sign_velocity)
    effects = library(options.effects)
    segments, split = _segments(model, s, fit_signals, holdout_signals, options)
    design = _design(context, effects, segments, n)

    def correlation(chosen, fit):
        for seg in segments:
            seg.correction = predict(context, chosen, fit.x, seg) if chosen else np.zeros_like(seg.residual)
        return _correlation(segments, design.weights)

    selection = forward(design, options.min_gain, options.alpha)
    chosen, tau_corr, dropped = prune(design, selection.chosen, correlation, options.alpha)
    design, chosen = refine(context, segments, design, chosen)  # Stribeck velocity, exact time shift
    final = solve(design, chosen)
    if chosen:  # also leaves each segment's correction at the final fit
        tau_corr = correlation(chosen, final)
    before = np.sqrt(design.held.c / max(design.held.count, 1))
    after = np.sqrt(design.held.mse(final.slots, final.x)) if chosen else before.copy()
    held_before = np.vstack([seg.residual[seg.held] for seg in segments])
    held_after = np.vstack([(seg.residual - seg.correction)[seg.held] for seg in segments])
    masks = [phases.labels(seg.signals.t[seg.held], seg.signals.q[seg.held], seg.signals.qd[seg.held],
                           seg.signals.qdd[seg.held]) for seg in segments if seg.held.any()]
    masks = {name: np.vstack([m[name] for m in masks]) for name in phases.PHASES}
    where = phases.by_phase(held_before, masks)
    after_phases = phases.by_phase(held_after, masks)
    for w, a in zip(where, after_phases):
        w["rms_after"] = a["rms"]
        for name, v in w["phases"].items():
            v["rms_after"] = a["phases"][name]["rms"]
    noise = np.std(np.diff(held_after, axis=0), axis=0) / np.sqrt(2)
    selected = [_describe(robot, design, chosen, final, c, tau_corr, options.min_gain) for c in chosen]
    candidates = [{"candidate": k, "heldout_gain": g} for k, g in
                  sorted(selection.first_gains.items(), key=lambda kv: -kv[1])]
    return Diagnosis(robot.name, n, split, selected, before.tolist(), after.tolist(),
                     np.abs(held_before).max(axis=0).tolist(), noise.tolist(), where, candidates, selection.steps,
                     dropped, tau_corr, segments)


def _correlation(segments, weights) -> float:
    """Integrated autocorrelation time of the final weighted fit residual, median over joints."""
    times = []
    for j, w in enumerate(weights):
        r = np.concatenate([(seg.residual - seg.correction)[seg.fit, j] for seg in segments])
        times.append(integrated_time(w * r))
    return float(np.median(times))


def _describe(robot, design, chosen, final, cand, tau_corr, min_gain) -> dict:
    from .values import derived

    offset = sum(c.size for c in chosen[:chosen.index(cand)])
    k = slice(offset, offset + cand.size)
    x = final.x[k]
    std = np.sqrt(np.maximum(np.diag(final.covariance)[k], 0.0) * tau_corr)
    identifiable = _identifiable(design, chosen, k)
    others = [c for c in chosen if c is not cand]
    rest = solve(design, others)
    mse_without = design.held.mse(rest.slots, rest.x) if others else design.held.c / max(design.held.count, 1)
    mse_with = design.held.mse(final.slots, final.x)
    gain_per_joint = (mse_without - mse_with) / np.maximum(mse_without, 1e-300)
    gain = heldout_gain(cand, mse_without, mse_with)
    joints = [cand.joint + 1] if cand.joint is not None else \
        [j + 1 for j in range(len(gain_per_joint)) if gain_per_joint[j] >= min_gain]
    names = list(cand.effect.parameters)
    values = {nm: (float(v) if ok else None) for nm, v, ok in zip(names, x, identifiable)}
    stds = {nm: (float(d) if ok else None) for nm, d, ok in zip(names, std, identifiable)}
    return {
        "effect": cand.effect.name, "joints": joints, "variant": cand.effect.fixed(),
        "values": values, "std": stds, "units": dict(zip(names, cand.effect.units)),
        "derived": derived(robot, cand.effect.name, values, stds),
        "heldout_gain": gain,
        "rms_before": np.sqrt(mse_without).tolist(), "rms_after": np.sqrt(mse_with).tolist(),
    }


def _identifiable(design, chosen, k) -> np.ndarray:
    """Values the data determine: not in the null space of the weighted normal matrix."""
    slots = np.concatenate([c.slots for c in chosen])
    H = design.H[np.ix_(slots, slots)]
    d = np.sqrt(np.maximum(np.diag(H), 1e-300))
    vals, vecs = np.linalg.eigh(H / np.outer(d, d))
    weak = vals <= 1e-10 * max(vals.max(), 1e-300)
    loading = (vecs[:, weak] ** 2).sum(axis=1)
    return loading[k] < 0.5
