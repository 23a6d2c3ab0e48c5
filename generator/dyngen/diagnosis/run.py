"""The diagnosis: residual, forward selection of effects on selection data, refinement of
their nonlinear settings, final fit, the simple model beside it, and the test.

    result = diagnose(robot, model, p, fit_signals, select_signals, options, test=test_signals)

fit_signals set the values, select_signals (default: blocks of the fit data) choose the
effects, test_signals are used for nothing but the reported held-out residual (roles.py).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from ..catalogue import STANDARD_FROM_DYNAMIC
from . import baseline as simple_model
from . import design as dz
from . import findings_check, joints, phases, reidentify, roles, trust
from ..data.correlation import integrated_time
from .effects import Context, effect_class, library
from .options import Options
from .refine import refine, restricted
from .selection import bases, forward, prune, relative_change, selection_gain, selection_mse, solve, without

EXTRAPOLATION = 1.2  # warn when test speeds exceed the fit data's by this factor
DIFFERENTIATION_SHARE = 0.5  # warn when differentiation noise is this share of a joint's residual variance


@dataclass
class Diagnosis:
    robot: str
    joints: int
    split: str  # how selection data were obtained
    judged_on: str  # "test" (recordings used for nothing else) or "selection" (no test data given)
    selected: list  # per chosen candidate: dict (see docs/conventions.md, diagnosis JSON)
    rms_before: list  # per joint, on the judged data, nominal model
    rms_after: list  # per joint, on the judged data, with the final model (effects; simple model where it won)
    rms_effects: list  # per joint, on the judged data, with the selected effects alone
    rms_simple: list  # per joint, on the judged data, the simple model (baseline.py)
    selection_before: list  # per joint, selection data
    selection_after: list
    selection_simple: list
    simple_wins: list  # 1-based joints where the simple model beat the effects on selection data
    # (joint_models below: per joint "effects", "simple" or "effects + simple", joints.py)
    simple_values: list  # per joint b, Fc, Fv
    peak_before: list
    noise_rms: list  # per joint estimate of the white part of the final judged residual
    where: list  # per joint: phases of the nominal judged residual (phases.by_phase), with rms_after
    candidates: list  # every candidate: its selection gain when tried alone
    steps: list
    dropped: list  # selected forward, then dropped as not significant (correlated residual)
    refused: list  # selected, then refused: implausible values once fitted with the others
    superseded: list  # per-joint effects on joints the simple model won
    correlation_samples: float  # integrated autocorrelation time used to scale the deviations
    warnings: list = field(default_factory=list)
    joint_models: list = field(default_factory=list)
    completed: dict = field(default_factory=dict)  # joint -> values of [its effects' columns, b, Fc, Fv]
    conditioning: list = field(default_factory=list)  # per recording: what was done to it
    segments: list = field(default_factory=list)  # roles.Segment, for figures
    # per joint on the judged data at the joint velocities the fit data covered: share of samples
    # beyond them, RMS of the final and of the simple model there (velocity laws extrapolate beyond)
    within_fit_speeds: dict = field(default_factory=dict)
    consistent: dict | None = None  # "link parameters off": reidentify.finding, where the consistent model won
    reidentified: object = None  # its identification.consistent.Consistent (for the written parameters)


@dataclass
class Design:
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


def _design(context, effects, segments, n) -> Design:
    candidates, moments = None, None
    for seg in segments:
        columns = dz.effect_columns(effects, context, seg)
        if candidates is None:
            candidates = dz.candidates_of(effects, n, {k: v.shape[2] for k, v in columns.items()})
            size = candidates[-1].start + candidates[-1].size
            moments = [dz.empty(n, size) for _ in range(3)]
            groups = [dz.empty(n, size) for _ in range(roles.FOLDS)]
        roles_here = [*zip(moments, (seg.fit, seg.select, seg.test)), *zip(groups, seg.groups or [])]
        for j in range(n):
            A, slots = dz.joint_matrix(candidates, columns, j)
            for m, mask in roles_here:
                if mask.any():
                    dz.accumulate(m, A[mask], slots, seg.residual[mask, j], j)
        for m, mask in roles_here:
            m.count += int(mask.sum())
    if moments[0].count == 0:
        raise ValueError("no fit samples (recordings too short for the filter's start-up?)")
    rms = np.sqrt(moments[0].c / max(moments[0].count, 1))
    weights = 1.0 / np.maximum(rms, 1e-9 * max(rms.max(), 1e-300))
    return Design(candidates, *moments, weights, groups if any(m.count for m in groups) else [])


def predict(context, chosen, x, segment) -> np.ndarray:
    """The chosen candidates' torques (T, N) on one segment, for fitted values x (in chosen order)."""
    effects = list({c.effect.key: c.effect for c in chosen}.values())
    columns = dz.effect_columns(effects, dz.as_chosen(context, chosen), segment)
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


def diagnose(robot, model, p, fit_signals, select_signals=None, options: Options = Options(),
             test=None) -> Diagnosis:
    p = np.asarray(p, dtype=float)
    s = model(STANDARD_FROM_DYNAMIC.name, p)
    n = robot.dof
    # --- hook (trust.py): a recording whose nominal residual exceeds its torques is conditioned
    # again, or raises trust.Unusable (nothing claimed)
    fit_signals, select_signals, test = trust.checked_roles(model, s, fit_signals, select_signals, test)
    # ---
    segments, split = roles.segments(model, s, fit_signals, select_signals, test, options.block_seconds)
    # Position- and velocity-dependent laws are known only over what the fit data cover.
    fit_q = np.vstack([seg.signals.q[seg.fit] for seg in segments if seg.fit.any()])
    fit_qd = np.vstack([seg.signals.qd[seg.fit] for seg in segments if seg.fit.any()])
    context = Context(model, robot, p, s, options.sign_velocity, (fit_q.min(axis=0), fit_q.max(axis=0)),
                      (fit_qd.min(axis=0), fit_qd.max(axis=0)))
    effects = library(context, options.effects)
    design = _design(context, effects, segments, n)

    def correlation(chosen, fit):
        for seg in segments:
            seg.correction = predict(context, chosen, fit.x, seg) if chosen else np.zeros_like(seg.residual)
        return _correlation(segments, design.weights)

    selection = forward(design, options.min_gain, options.alpha)
    design, chosen, final, dropped, refused = _settled(context, segments, design, selection.chosen, correlation,
                                                       options)
    if chosen:
        # Once more with each joint weighted by what the effects leave of its residual: an
        # effect kept only to make up for another fitted with the nominal weights goes now.
        design, chosen, final, dropped_now, refused_now = _settled(
            context, segments, _reweighted(design, final), chosen, correlation, options)
        dropped += dropped_now
        refused += refused_now
    correlation(chosen, final)  # each segment's correction: the effects at values from the fit samples
    # Per joint: the effects, the simple model or both, all fitted on the fit samples only and
    # compared on the selection samples (joints.py).
    simple = simple_model.fit(segments)
    sel_before = selection_mse(design, [])
    sel_effects = selection_mse(design, chosen)
    sel_simple = _simple_mse(segments, simple, "select", n)
    if not design.select.count:
        modes = [joints.EFFECTS] * n
    elif select_signals:
        modes = joints.decide(context, segments, chosen, final.x, simple, options.min_gain)
    else:
        modes = _decide_on_folds(context, segments, design, chosen, final, options)
    reid, consistent = None, None
    # --- hook (issue 25): without the re-identification its cheap gate still says where the rigid
    # body's columns explain what the effects leave: the link parameters may be off there
    links_hint = []
    if not options.reidentify and design.select.count and all(seg.correction is not None for seg in segments):
        links_hint = reidentify.gate(model, segments, [seg.residual - seg.correction for seg in segments],
                                     options.min_gain)
    # ---
    if options.reidentify and design.select.count:
        reid, consistent, modes = _reidentified(robot, model, p, context, segments, chosen, final.x, simple, modes,
                                                options.min_gain)
    wins = [j for j in range(n) if modes[j] == joints.SIMPLE]
    replaced = [j for j in range(n) if modes[j] in (joints.SIMPLE, joints.CONSISTENT)]
    described = [_describe(robot, design, chosen, final, c, options.min_gain) for c in chosen]
    # The choice made, every sample of the fit recordings sets the values (selection blocks
    # included; separate selection recordings stay out of it, as test recordings do).
    if not select_signals:
        for seg in segments:
            seg.fit = seg.fit | seg.select
        simple = simple_model.fit(segments)
        # position laws now known over every fit sample's positions
        context = _ranged(context, segments, chosen)
        if chosen:
            design, chosen = restricted(context, segments, design, chosen)
            final = solve(design, chosen)
        if reid is not None:
            reid, consistent = _refit(robot, model, p, segments, reid, consistent)
    tau_corr = correlation(chosen, final)  # also leaves each segment's correction at the final fit
    _values(described, design, chosen, final, tau_corr, robot)
    judged = "test" if design.test.count else "selection"
    judged_moments = design.test if judged == "test" else design.select
    before = judged_moments.c / max(judged_moments.count, 1)
    effects_mse = judged_moments.mse(final.slots, final.x) if chosen else before.copy()
    simple_mse = _simple_mse(segments, simple, "test" if judged == "test" else "select", n)
    completed = joints.apply(context, segments, chosen, final.x, simple, modes, consistent)
    mask = (lambda seg: seg.test) if judged == "test" else (lambda seg: seg.select)
    used = [seg for seg in segments if mask(seg).any()]
    held_before = np.vstack([seg.residual[mask(seg)] for seg in used])
    held_after = np.vstack([(seg.residual - seg.correction)[mask(seg)] for seg in used])
    after = np.mean(held_after ** 2, axis=0)
    masks = [phases.labels(seg.signals.t[mask(seg)], seg.signals.q[mask(seg)], seg.signals.qd[mask(seg)],
                           seg.signals.qdd[mask(seg)]) for seg in used]
    masks = {name: np.vstack([m[name] for m in masks]) for name in phases.PHASES}
    where = phases.by_phase(held_before, masks)
    for w, a in zip(where, phases.by_phase(held_after, masks)):
        w["rms_after"] = a["rms"]
        for name, v in w["phases"].items():
            v["rms_after"] = a["phases"][name]["rms"]
    noise = np.std(np.diff(held_after, axis=0), axis=0) / np.sqrt(2)
    selected, superseded = [], []
    for c, e in zip(chosen, described):
        if c.joint is not None and c.joint in replaced:
            superseded.append(e)
            continue
        e["joints"] = [j for j in e["joints"] if j - 1 not in replaced]
        selected.append(e)
    candidates = [{"candidate": k, "selection_gain": g} for k, g in
                  sorted(selection.first_gains.items(), key=lambda kv: -kv[1])]
    result = Diagnosis(
        robot.name, n, split, judged, selected, *(np.sqrt(x).tolist() for x in (before, after, effects_mse, simple_mse)),
        *(np.sqrt(x).tolist() for x in (sel_before, sel_effects, sel_simple)), [j + 1 for j in wins],
        simple.values.tolist(), np.abs(held_before).max(axis=0).tolist(), noise.tolist(), where, candidates,
        selection.steps, dropped, refused, superseded, tau_corr, segments=segments)
    result.joint_models = modes
    result.within_fit_speeds = _within_fit_speeds(segments, simple, used, mask)
    result.completed = completed
    if reid is not None:
        result.consistent = reidentify.finding(robot, reid, [j for j in range(n) if modes[j] == joints.CONSISTENT])
        result.reidentified = reid
    result.conditioning = [{"recording": sig.name, "role": role, "note": sig.note, "trimmed_samples": sig.trim}
                           for role, group in (("fit", fit_signals), ("select", select_signals or []),
                                               ("test", test or [])) for sig in group]
    # --- hook (findings_check.py): findings outside their physical range are marked suspect
    apart = findings_check.check(result, model, s, fit_signals)
    # ---
    if links_hint:
        apart.append("the link parameters may be off: on joint(s) " + ", ".join(str(j + 1) for j in links_hint)
                     + " the rigid body's own columns explain what the effects leave on selection data, so the "
                     "effects found there may stand for wrong masses or inertias; --reidentify tries consistent link "
                     "parameters as an alternative (or identify them first: dyngen identify)")
    result.warnings = _warnings(result, model, s, fit_signals, select_signals or [], test or [], used) + apart
    return result


def _settled(context, segments, design, chosen, correlation, options):
    """The selected effects with their settings refined, those that no longer pay for their
    values pruned, implausible ones refused: (design, chosen, final fit, dropped, refused)."""
    # Settings first (velocity scales, exact time shift and tilt), then pruning: a Stribeck term
    # that only made up for a Coulomb velocity scale on its variant grid goes once the scale is fitted.
    design, chosen = refine(context, segments, design, chosen)
    before = chosen
    chosen, _, dropped = prune(design, chosen, correlation, options.alpha, options.min_gain)
    narrow = _narrow_stribeck(chosen)
    chosen = [c for c in chosen if c not in narrow]
    dropped += [f"{c.key} (no wider than the joint's Coulomb transition: it only reshapes it)" for c in narrow]
    if dropped:
        if _moved(context, chosen, before):
            design, chosen = restricted(context, segments, design, chosen)
        design, chosen = refine(context, segments, design, chosen)
    before = chosen
    chosen, final, refused = _plausible(design, chosen)
    if _moved(context, chosen, before):
        design, chosen = restricted(context, segments, design, chosen)
        final = solve(design, chosen)
    design, chosen, final = _consistent_payload(context, segments, design, chosen, final, refused)
    return design, chosen, final, dropped, refused


def _moved(context, chosen, before) -> bool:
    """Whether dropping some of `before` changed what the others' columns are computed with
    (design.world: a time shift, a gain or a payload went): then the design is rebuilt."""
    return dz.world(context, chosen) != dz.world(context, before)


def _decide_on_folds(context, segments, design, chosen, final, options) -> list[str]:
    """Per joint model (joints.py) from its selection errors summed over the roles.FOLDS ways of
    cutting the fit recordings into fit and selection blocks, each model refitted per fold. One
    cut selects on one phase of the motion only (on a periodic trajectory, the same stretch
    every period); every sample judges once this way. Leaves the segments' masks and
    corrections as they were."""
    saved = [(seg.fit, seg.select, seg.correction) for seg in segments]
    own = [seg.fit.any() or seg.select.any() for seg in segments]
    totals = None
    try:
        for phase in range(roles.FOLDS):
            for seg, mine in zip(segments, own):
                if mine:
                    seg.fit, seg.select = roles.blocks(seg.signals, options.block_seconds, phase)
            # Position laws are known only over the positions this cut's fit blocks cover, as the
            # final model's are over all the fit data (else a ripple would be judged on guesses).
            fold = _ranged(context, segments, chosen)
            x = np.zeros(0)
            if chosen:
                fold_design, fold_chosen = restricted(fold, segments, design, chosen)
                x = solve(fold_design, fold_chosen, covariance=False).x
            for seg in segments:
                seg.correction = predict(fold, chosen, x, seg) if chosen else np.zeros_like(seg.residual)
            sse = joints.errors(fold, segments, chosen, x, simple_model.fit(segments))
            totals = sse if totals is None else [{k: a[k] + b[k] for k in a} for a, b in zip(totals, sse)]
    finally:
        for seg, (fit, select, correction) in zip(segments, saved):
            seg.fit, seg.select, seg.correction = fit, select, correction
    return joints.choose(totals, chosen, joints.FOLDS_PER_VALUE)


def _ranged(context, segments, chosen):
    """The context with the positions the segments' fit samples cover (Context.q_range), if a
    chosen effect depends on them (Effect.ranged); else the context itself (and its cache)."""
    if not any(c.effect.ranged for c in chosen):
        return context
    q = np.vstack([seg.signals.q[seg.fit] for seg in segments if seg.fit.any()])
    return dataclasses.replace(context, q_range=(q.min(axis=0), q.max(axis=0)), cache={})


def _reidentified(robot, model, p, context, segments, chosen, x, simple, modes, min_gain):
    """(Consistent result, its corrections per segment, modes) where the consistent link
    parameters win a joint on selection data, else (None, None, modes) (reidentify.py)."""
    remaining = [seg.residual - seg.correction for seg in segments]  # after the effects (fit-only values)
    flagged = reidentify.gate(model, segments, remaining, min_gain)
    if not flagged:
        return None, None, modes
    result = reidentify.identify(robot, model, p, reidentify.pieces(segments, "fit"),
                                 reidentify.pieces(segments, "select"))
    consistent = reidentify.corrections(result, model, segments)
    new = joints.decide(context, segments, chosen, x, simple, min_gain, consistent, reidentify.JOINT_VALUES)
    # only on joints whose residual the link parameters were shown to explain (the gate)
    new = [m if m != joints.CONSISTENT or j in flagged else old for j, (m, old) in enumerate(zip(new, modes))]
    if joints.CONSISTENT not in new:
        return None, None, modes
    return result, consistent, new


def _refit(robot, model, p, segments, reid, consistent):
    """The consistent model refitted on every fit sample (selection blocks included), its
    regularisation as chosen; kept only if it fits about as well as the model from the fit
    blocks alone (reidentify.REFIT_WORSE), else that model stays."""
    refit = reidentify.identify(robot, model, p, reidentify.pieces(segments, "fit"), regularisation=reid.regularisation)
    if np.all(refit.residual_rms <= reidentify.REFIT_WORSE * reid.residual_rms):
        return refit, reidentify.corrections(refit, model, segments)
    return reid, consistent


def _reweighted(design, final) -> Design:
    """The design with each joint weighted by 1 / the RMS its residual keeps after the chosen
    effects (on the fit samples). The selection's weights come from the nominal residual, which
    holds the very effects sought: a payload's 9 Nm on joint 2 would weigh joint 2 down as if
    it were noise, and the arm-wide values would be set by the other joints alone."""
    rms = np.sqrt(design.fit.mse(final.slots, final.x))
    weights = 1.0 / np.maximum(rms, 1e-9 * max(rms.max(), 1e-300))
    return Design(design.candidates, design.fit, design.select, design.test, weights, design.groups)


def _plausible(design, chosen):
    """The final fit, after refusing (one at a time, the worst first) effects whose values,
    fitted together, are no longer physically possible (e.g. a payload of negative mass)."""
    refused = []
    while True:
        final = solve(design, chosen)
        values = dict(zip(map(id, chosen), dz.split_values(chosen, final.x)))
        reasons = {}
        for c in chosen:
            if not c.effect.plausible(values[id(c)]):
                reasons[id(c)] = ""
            for base in bases(c, chosen):
                why = c.effect.refusal_beside(values[id(c)], values[id(base)])
                if why:
                    reasons[id(c)] = f"beside {base.key} at {', '.join(f'{v:.3g}' for v in values[id(base)])}: {why}"
        bad = [c for c in chosen if id(c) in reasons]
        if not bad:
            return chosen, final, refused
        worst = bad[0]
        refused.append({"candidate": worst.key, "values": values[id(worst)].tolist()}
                       | ({"reason": reasons[id(worst)]} if reasons[id(worst)] else {}))
        chosen, gone = without(chosen, worst)  # a Stribeck term whose Coulomb was refused goes with it
        refused += [{"candidate": c.key, "values": [], "reason": f"{worst.key} refused"} for c in gone[1:]]


def _consistent_payload(context, segments, design, chosen, final, refused):
    """An effect whose fitted values are possible only in part (Effect.simplified: a payload
    whose inertia is no body's) is replaced by the simpler form that does best on the
    selection data (weighted as the fit), and everything refitted."""
    offset = 0
    for i, c in enumerate(chosen):
        values = final.x[offset: offset + c.size]
        offset += c.size
        simpler = c.effect.simplified(values)
        if simpler is None:
            continue
        refusal, forms = simpler
        options = []
        for effect in forms:
            replaced = chosen[:i] + [dz.Candidate(effect, c.joint, 0, len(effect.parameters))] + chosen[i + 1:]
            form_design, form_chosen = restricted(context, segments, design, replaced)
            score = float(design.weights ** 2 @ selection_mse(form_design, form_chosen))
            options.append((score, form_design, form_chosen))
        _, design, chosen = min(options, key=lambda o: o[0])
        refused.append(refusal)
        return design, chosen, solve(design, chosen)
    return design, chosen, final


def _narrow_stribeck(chosen) -> list:
    """Per-joint effects that only reshape another on their joint (Effect.reshapes: a Stribeck
    term no wider than the Coulomb transition)."""
    return [c for c in chosen if c.joint is not None
            and any(o.joint == c.joint and c.effect.reshapes(o.effect) for o in chosen)]


def _within_fit_speeds(segments, simple, used, mask) -> dict:
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


def _simple_mse(segments, simple, role, n) -> np.ndarray:
    sse, count = np.zeros(n), 0
    for seg in segments:
        m = getattr(seg, role)
        if m.any():
            r = seg.residual[m] - simple_model.predict(simple, seg)[m]
            sse += (r ** 2).sum(axis=0)
            count += int(m.sum())
    return sse / max(count, 1)


def _warnings(d, model, s, fit_signals, select_signals, test_signals, used) -> list[str]:
    out = []
    for sig in [*fit_signals, *select_signals, *test_signals]:
        out += sig.warnings
    if d.judged_on == "selection":
        out.append("no test recording (--test): the residual 'after' is measured on the selection data, which chose "
                   "the effects; it is not a held-out figure")
    # Laws fitted on one range of motion and judged beyond it (friction at higher speeds).
    if test_signals:
        fast_fit = np.max(np.vstack([np.abs(sig.qd[sig.inner()]) for sig in fit_signals]), axis=0)
        fast_test = np.max(np.vstack([np.abs(sig.qd[sig.inner()]) for sig in test_signals]), axis=0)
        beyond = [j for j in range(d.joints) if fast_test[j] > EXTRAPOLATION * fast_fit[j]]
        if beyond:
            out.append("the test data move joint(s) " + ", ".join(
                f"{j + 1} ({fast_test[j]:.2g} vs {fast_fit[j]:.2g} rad/s)" for j in beyond)
                + " faster than any fit data: velocity-dependent laws are extrapolated there")
    for fit, test, diff in roles.repeated(fit_signals, test_signals):
        out.append(f"{test} repeats the trajectory of {fit} (RMS position difference {diff:.3g} rad): the test shows "
                   "that the effects repeat, not that they generalise to other motions")
    # Differentiation noise carried into the model torque: M(q) times the acceleration noise.
    for seg in used:
        sig = seg.signals
        if sig.qdd_noise is None:
            continue
        M = model("mass_matrix", np.median(sig.q, axis=0), s).reshape(d.joints, d.joints)
        predicted = np.sqrt((M ** 2) @ (np.asarray(sig.qdd_noise) ** 2))
        bad = [j for j in range(d.joints) if predicted[j] ** 2 > DIFFERENTIATION_SHARE * d.rms_after[j] ** 2]
        if bad:
            out.append(f"{sig.name}: noise of the differentiated positions makes up most of the residual on joint(s) "
                       f"{', '.join(str(j + 1) for j in bad)} (about "
                       f"{', '.join(f'{predicted[j]:.3g}' for j in bad)} Nm of {', '.join(f'{d.rms_after[j]:.3g}' for j in bad)}"
                       " Nm): recorded velocities, or a lower --cutoff, would lower it")
    for e in d.selected:
        out += effect_class(e["effect"]).warnings(e)
        if e.get("suspect"):
            out.append(f"{e['effect']} is a symptom, not a cause: {e['suspect']}")
    for r in d.refused:
        shown = ", ".join(f"{v:.3g}" for v in r["values"][:4])
        because = "; ".join(x for x in (shown, r.get("reason", "")) if x)
        what = "" if r.get("reason") else ", its fitted values are not physically possible"
        out.append(f"{r['candidate']}: refused{what} ({because})")
    if d.consistent:
        c = d.consistent
        out.append("link parameters off: on joint(s) " + ", ".join(map(str, c["joints"])) + " physically consistent "
                   "link parameters re-identified from the fit data (with friction, offsets, rotor inertia and a "
                   f"tilted base; regularised toward the given parameters with weight {c['regularisation']:g}, chosen "
                   "on selection data) did better than every effect and the simple model on selection data, and "
                   "are used there; they are written out (consistent/)")
    if d.simple_wins:
        out.append("on joint(s) " + ", ".join(map(str, d.simple_wins)) + " the simple model (offset + Coulomb + viscous) "
                   "did better than the selected effects on selection data and is kept there")
    return out


def _correlation(segments, weights) -> float:
    """Integrated autocorrelation time of the final weighted fit residual, median over joints."""
    times = []
    for j, w in enumerate(weights):
        r = np.concatenate([(seg.residual - seg.correction)[seg.fit, j] for seg in segments])
        times.append(integrated_time(w * r))
    return float(np.median(times))


def _values(described, design, chosen, final, tau_corr, robot) -> None:
    """The final values of every chosen effect, with deviations scaled for the residual's
    correlation in time, and what follows from them (Effect.derived)."""
    offset = 0
    for cand, e in zip(chosen, described):
        k = slice(offset, offset + cand.size)
        offset += cand.size
        std = np.sqrt(np.maximum(np.diag(final.covariance)[k], 0.0) * tau_corr)
        identifiable = _identifiable(design, chosen, k)
        names = list(cand.effect.parameters)
        e["values"] = {nm: (float(v) if ok else None) for nm, v, ok in zip(names, final.x[k], identifiable)}
        e["std"] = {nm: (float(d) if ok else None) for nm, d, ok in zip(names, std, identifiable)}
        e["variant"] = cand.effect.fixed()
        e["derived"] = cand.effect.derived(robot, e["values"], e["std"], partial(_torque_rms, design, cand, final.x[k]))


def _torque_rms(design, cand, x) -> float:
    """RMS torque of a per-joint candidate's values x on its joint over the fit samples."""
    G = design.fit.G[cand.joint][np.ix_(cand.slots, cand.slots)]
    return float(np.sqrt(max(x @ G @ x, 0.0) / max(design.fit.count, 1)))


def _describe(robot, design, chosen, final, cand, min_gain) -> dict:
    """What an effect does on the selection data (its gain, the joints it helps); its values
    are filled in by _values once the final fit is made."""
    mse_without = selection_mse(design, [c for c in chosen if c is not cand])
    mse_with = selection_mse(design, chosen)
    gain_per_joint = relative_change(mse_without, mse_with)
    gain = selection_gain(cand, mse_without, mse_with)
    joints = [cand.joint + 1] if cand.joint is not None else \
        [j + 1 for j in range(len(gain_per_joint)) if gain_per_joint[j] >= min_gain]
    names = list(cand.effect.parameters)
    out = {
        "effect": cand.effect.name, "joints": joints, "variant": cand.effect.fixed(),
        "values": {}, "std": {}, "units": dict(zip(names, cand.effect.units)), "derived": {},
        "selection_gain": gain,
        "rms_before": np.sqrt(mse_without).tolist(), "rms_after": np.sqrt(mse_with).tolist(),
    }
    if cand.effect.suspect:
        out["suspect"] = cand.effect.suspect
    return out


def _identifiable(design, chosen, k) -> np.ndarray:
    """Values the data determine: not in the null space of the weighted normal matrix."""
    slots = np.concatenate([c.slots for c in chosen])
    H = design.H[np.ix_(slots, slots)]
    d = np.sqrt(np.maximum(np.diag(H), 1e-300))
    vals, vecs = np.linalg.eigh(H / np.outer(d, d))
    weak = vals <= 1e-10 * max(vals.max(), 1e-300)
    loading = (vecs[:, weak] ** 2).sum(axis=1)
    return loading[k] < 0.5
