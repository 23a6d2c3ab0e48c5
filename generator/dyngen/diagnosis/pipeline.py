"""The diagnosis's stages run in order (listed with their modules, and the call, in diagnosis/__init__.py).
Each stage's result is a new value (the segments frozen: roles.Segment); stages 3 and 4 and the
final fit are the functions below diagnose, each returning one record (Settled, Choice, Final).

fit_signals set the values, select_signals (default: blocks of the fit data) choose the
effects, test_signals are used for nothing but the reported held-out residual (roles.py).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..catalogue import STANDARD_FROM_DYNAMIC
from ..terms import Context, library, simple_model
from ..data import trust
from . import across, choose, every_row, findings_check, fit, joints, reidentify, roles, stable
from .diagnose_options import Options
from .findings import describe, reported, with_values
from .forward_selection import forward, selection_mse, solve
from .judge import judge, simple_mse
from .notes import notes
from .record import CandidateGain, Diagnosis, RecordingNote, Unstable
from .refine import restricted
from .settle import settle

ALIKE = ("; the model's torques filtered alike (the positions' noise above twice the cutoff exceeds twice its white "
         "estimate: the accelerations carry more noise than the cutoff allowed for)")


def diagnose(robot, model, p, fit_signals, select_signals=None, options: Options = Options(),
             test=None) -> Diagnosis:
    p = np.asarray(p, dtype=float)
    s = model(STANDARD_FROM_DYNAMIC.name, p)
    # 0. roles; a recording whose nominal residual exceeds its torques is conditioned again, or
    # trust.Unusable is raised (nothing claimed)
    fit_signals, select_signals, test = trust.checked_roles(model, s, fit_signals, select_signals, test)
    segments, split = roles.segments(model, s, fit_signals, select_signals, test, options.block_seconds)
    # position-dependent laws are known only over the positions the fit data cover
    context = Context(model, robot, p, s, options.sign_velocity, fit.positions(segments))
    # 1. fit: the moments of every candidate on every role's samples
    design = fit.build(context, library(context, options.effects), segments, robot.dof)
    # 2. select
    selection = forward(design, options.min_gain, options.alpha)
    # 3. settle
    settled = _settle(context, segments, design, selection.chosen, options)
    # 4. choose, per joint; then the final fit
    floors = findings_check.floor(fit_signals)  # Nm per joint: a torque below it is no finding
    choice = _choose(robot, model, p, context, segments, settled, bool(select_signals), options, floors)
    final = _final_fit(robot, model, p, context, settled, choice, bool(select_signals))
    # 5. test: each joint's correction by the model it was given, judged on the judged data
    judged_segments, completed = joints.apply(final.context, final.segments, final.chosen, final.fit.x, final.simple,
                                              choice.modes, final.consistent)
    judged = judge(final.design, judged_segments, final.chosen, final.fit, final.simple)
    judged = every_row.every_test_row(model, final, choice.modes, completed, judged, judged_segments)
    # 6. report
    roles_of = (("fit", fit_signals), ("select", select_signals or []), ("test", test or []))
    result = _result(robot, model, s, split, selection, settled, choice, final, judged, judged_segments, completed,
                     roles_of, options.min_gain, floors)
    return replace(result, warnings=notes(result, model, s, fit_signals, select_signals or [], test or [],
                                          judged.used) + result.warnings)


@dataclass(frozen=True)
class Settled:
    """Stage 3's result: the chosen effects refined, pruned and checked, fitted on the fit samples."""
    design: object  # fit.CandidateMoments
    chosen: list  # moments.Candidate
    fit: object  # forward_selection's fit of the chosen (x, covariance, slots)
    dropped: list  # selected, then dropped as not significant
    refused: list  # record.Refusal


def _settle(context, segments, design, chosen, options) -> Settled:
    """settle.py, then once more with each joint weighted by what the effects leave of its
    residual: an effect kept only to make up for another fitted with the nominal weights goes."""

    def correlation(chosen, fitted):
        """The correlation time of what the chosen effects at the fitted values leave (with the
        design of the round before: `design` as bound when called)."""
        return fit.correlation_time(fit.corrected(context, chosen, fitted.x, segments), design.weights)

    design, chosen, final, dropped, refused = settle(context, segments, design, chosen, correlation, options)
    if chosen:
        reweighted, chosen, final, dropped_now, refused_now = settle(
            context, segments, fit.reweighted(design, final), chosen, correlation, options)
        design, dropped, refused = reweighted, dropped + dropped_now, refused + refused_now
    return Settled(design, chosen, final, dropped, refused)


@dataclass(frozen=True)
class Choice:
    """Stage 4's result: per joint the model it is given, chosen on the selection samples."""
    segments: list  # the segments with the effects' torques at the values from the fit samples
    simple: object  # terms.simple_model fit on the fit samples
    modes: list  # per joint: joints.EFFECTS, SIMPLE, TIED, COMPLETED or CONSISTENT
    reidentified: object  # identification.consistent.Consistent where it won a joint, else None
    consistent: list | None  # per segment its corrections (T, N), with reidentified
    links_hint: list  # 0-based joints where the rigid body's columns explain what the effects leave
    precision: float | None  # reidentify.gate's precision where it left the re-identification off by default
    described: list  # record.Finding per chosen effect, values not yet filled in
    selection_mse: dict  # "before", "effects", "simple": per joint, on the selection samples
    tried: object = None  # the re-identification's result wherever it ran, won a joint or not


def _choose(robot, model, p, context, segments, settled, separate_selection, options, floors=None) -> Choice:
    """The effects, the simple model or both, all fitted on the fit samples only and compared
    on the selection samples (joints.py; on folds of the fit recordings without separate
    selection recordings, choose.py), or re-identified link parameters (--reidentify)."""
    design, chosen, final, n = settled.design, settled.chosen, settled.fit, robot.dof
    selecting = fit.corrected(context, chosen, final.x, segments)
    simple = simple_model.fit(selecting)
    mse = {"before": selection_mse(design, []), "effects": selection_mse(design, chosen),
           "simple": simple_mse(selecting, simple, "select", n)}
    if not design.select.count:
        modes = [joints.EFFECTS] * n
    elif separate_selection:
        modes = joints.decide(context, selecting, chosen, final.x, simple, options.min_gain)
    else:
        modes = choose.on_folds(context, selecting, design, chosen, options)
    reid, consistent, links_hint, off_by_default, tried = None, None, [], None, None
    if design.select.count:  # the gate: where the rigid body's columns explain what the effects leave
        flagged, precision, hint = across.gated(model, context, selecting, chosen, final.x, options.min_gain, floors)
        run_reid = precision <= reidentify.PRECISION if options.reidentify is None else options.reidentify
        if run_reid:
            reid, consistent, modes, tried = choose.reidentified(robot, model, p, context, selecting, chosen, final.x,
                                                                 simple, modes, options.min_gain, flagged)
        else:  # the link parameters may be off there
            links_hint, off_by_default = hint, (None if options.reidentify is False else precision)
    described = [describe(design, chosen, c, options.min_gain) for c in chosen]
    return Choice(selecting, simple, modes, reid, consistent, links_hint, off_by_default, described, mse, tried)


@dataclass(frozen=True)
class Final:
    """The final fit: the choice made, on every fit sample."""
    context: Context
    design: object
    chosen: list
    fit: object
    simple: object
    segments: list  # with the effects' torques at the final values
    reidentified: object
    consistent: list | None
    correlation_samples: float  # of the final fit residual (scales the deviations)
    findings: list  # record.Finding per chosen effect, with its values


def _final_fit(robot, model, p, context, settled, choice, separate_selection) -> Final:
    """Every sample of the fit recordings sets the values (selection blocks included; separate
    selection recordings stay out of it, as test recordings do); of a long recording diagnosed
    on windows, every row of it (every_row)."""
    design, chosen, final, simple = settled.design, settled.chosen, settled.fit, choice.simple
    reid, consistent, fitting = choice.reidentified, choice.consistent, choice.segments
    if not separate_selection:
        fitting = [replace(seg, fit=seg.fit | seg.select) for seg in fitting]
        simple = simple_model.fit(fitting)
        context = fit.ranged(context, fitting, chosen)  # position laws known over every fit sample's positions
        if chosen:
            design, chosen = restricted(context, fitting, design, chosen)
            final = solve(design, chosen)
        if reid is not None:
            reid, consistent = choose.refit(robot, model, p, fitting, reid, consistent)
    streams = every_row.streams_of([seg for seg in fitting if seg.fit.any()])  # not the --select or --test windows
    if streams and chosen:  # windows of long recordings: the values from every row of them
        design = replace(design, fit=every_row.every_row(context, chosen, streams, design.fit.G.shape[1]))
        final = solve(design, chosen)
    fitted = fit.corrected(context, chosen, final.x, fitting)
    tau_corr = fit.correlation_time(fitted, design.weights)
    findings = with_values(choice.described, design, chosen, final, tau_corr, robot)
    return Final(context, design, chosen, final, simple, fitted, reid, consistent, tau_corr, findings)


def _why_not_tried(precision) -> str:
    """Why the gate's re-identification did not run by default ("" where it was asked not to)."""
    if precision is None:
        return ""
    if np.isinf(precision):
        return (f"; not tried by default: no base coefficient alone carries {reidentify.MOVED:g} of what the effects "
                "leave (a weak sign: the gain is spread over many)")
    return (f"; not tried by default: the fit data do not determine the base coefficients it would move (relative "
            f"standard deviation up to {precision:.3g}, above {reidentify.PRECISION:g})")


def _result(robot, model, s, split, selection, settled, choice, final, judged, judged_segments, completed,
            roles_of, min_gain, floors=None) -> Diagnosis:
    """The record: the findings (those on joints another model won superseded; those outside
    their range marked suspect, findings_check.py), the figures, and the warnings of the checks
    (notes.py's are added by diagnose)."""
    n, modes = robot.dof, choice.modes
    replaced = [j for j in range(n) if modes[j] in (joints.SIMPLE, joints.CONSISTENT)]
    low = findings_check.below_floor(final.context, final.segments, final.chosen, final.fit.x, floors)
    flagged = stable.unstable(final.context, final.segments, final.design, final.chosen, final.fit.x,
                              final.correlation_samples, faint=list(low))
    claimed = [i for i, c in enumerate(final.chosen) if (i not in flagged or c.joint in replaced) and i not in low]
    explained = [] if choice.tried is None else across.explained_by_links(
        final.context, choice.segments, reidentify.link_corrections(choice.tried, model, choice.segments),
        settled.design, settled.chosen, min_gain)
    explained = [i for i in explained if final.chosen[i].joint not in replaced]  # those are superseded anyway
    # links that won no joint explain them as well as they do: claimed, flagged (a true sensor gain
    # on joint 2 of the LWR is also a change of its links); links that won a joint supersede them
    marked, explained = (explained, []) if choice.reidentified is None else ([], explained)
    if choice.tried is not None:  # gains the base columns make: flagged, not superseded
        marked = sorted(set(marked) | {i for i in across.made_by_base_columns(
            model, final.context, choice.segments, settled.chosen, settled.fit.x, min_gain)
            if i not in explained and final.chosen[i].joint not in replaced})
    sticking = findings_check.static_not_shown(final.context, final.segments, final.chosen, final.fit.x,
                                               final.correlation_samples)
    findings = [replace(f, suspect=across.LINKS) if i in marked else replace(f, suspect=sticking[i]) if i in sticking
                else f for i, f in enumerate(final.findings)]
    selected, superseded = reported([final.chosen[i] for i in claimed if i not in explained],
                                    [findings[i] for i in claimed if i not in explained], replaced)
    unstable = [Unstable(final.findings[i], *flagged[i]) for i in sorted(set(flagged) - set(claimed) - set(low))]
    faint = [f"{final.chosen[i].key} (a torque of {rms:.2g} Nm RMS, below the significance floor of "
             f"{floors[final.chosen[i].joint or 0]:.2g} Nm)" for i, rms in low.items()]
    superseded += [replace(final.findings[i], suspect=across.LINKS) for i in explained if i in claimed]
    selection_rms = {key: np.sqrt(x).tolist() for key, x in choice.selection_mse.items()}
    selected, apart = findings_check.check(selected, selection_rms["before"], model, s, roles_of[0][1])
    for which, so in ((explained, "so not claimed"), (marked, "flagged (those links won no joint)")):
        told = [final.chosen[i] for i in which]
        if told:
            apart.append("not told apart from the link parameters being off (the re-identified links' rigid body "
                         f"explains them: beside it each gains less than {min_gain:g} of the selection data's mean "
                         f"square), {so}: "
                         + "; ".join(c.effect.name + ("" if c.joint is None else f" on joint {c.joint + 1}") for c in told)
                         + ("; a payload is a change of the last link's parameters: a control run without it "
                            "(--control) tells them apart" if any(c.effect.name == "payload" for c in told) else ""))
    if faint:
        apart.append(f"below the significance floor, not findings (kept in the model): {'; '.join(faint)}; the floor is "
                     f"{findings_check.FLOOR:g} of the torque sensor's noise sigma per joint, from the raw torques: "
                     + " ".join(f"{x:.2g}" for x in floors) + " Nm")
    if choice.links_hint:
        apart.append("the link parameters may be off: on joint(s) " + ", ".join(str(j + 1) for j in choice.links_hint)
                     + " the rigid body's own columns explain what the effects leave on selection data, so the "
                     "effects found there may stand for wrong masses or inertias; --reidentify tries consistent link "
                     "parameters as an alternative (or identify them first: dyngen identify)"
                     + _why_not_tried(choice.precision))
    rms = {f"rms_{key}": np.sqrt(getattr(judged, key)).tolist() for key in ("before", "after", "effects", "simple")}
    reid = final.reidentified
    return Diagnosis(
        robot=robot.name, joints=n, split=split, judged_on=judged.on, selected=selected, **rms,
        selection_before=selection_rms["before"], selection_after=selection_rms["effects"],
        selection_simple=selection_rms["simple"],
        simple_wins=[j + 1 for j in range(n) if modes[j] == joints.SIMPLE], simple_values=final.simple.values.tolist(),
        peak_before=judged.peak_before.tolist(), noise_rms=judged.noise.tolist(), where=judged.where,
        candidates=[CandidateGain(k, g) for k, g in sorted(selection.first_gains.items(), key=lambda kv: -kv[1])],
        steps=selection.steps, dropped=settled.dropped + faint, refused=settled.refused, superseded=superseded, unstable=unstable,
        correlation_samples=final.correlation_samples, segments=judged_segments, joint_models=modes,
        within_fit_speeds=judged.within_fit_speeds, completed=completed,
        consistent=None if reid is None else reidentify.finding(reid, [j for j in range(n) if modes[j] == joints.CONSISTENT]),
        reidentified=reid,
        conditioning=[RecordingNote(sig.name, role, sig.note + ALIKE * sig.model_filtered, sig.trim)
                      for role, group in roles_of for sig in group],
        warnings=apart)
