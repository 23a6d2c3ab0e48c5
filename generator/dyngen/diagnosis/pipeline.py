"""The diagnosis as a pipeline of stages, each a module with its inputs and outputs:

    0. roles      the recordings cut into fit, selection and test samples (roles.py)
    1. fit        the moments of every candidate effect (fit.py, moments.py)
    2. select     forward selection on the selection data (selection.py)
    3. settle     settings refined, insignificant effects pruned, implausible ones refused
                  (settle.py, refine.py), once more with each joint weighted by what is left
    4. choose     per joint: the effects, the simple model (terms/simple_model.py), both, or re-identified
                  link parameters (choose.py, joints.py, reidentify.py); then the final fit on
                  every fit sample
    5. test       the figures on the judged data (judge.py, phases.py)
    6. report     the findings (findings.py) and warnings (notes.py) in one record (record.py)

    result = diagnose(robot, model, p, fit_signals, select_signals, options, test=test_signals)

fit_signals set the values, select_signals (default: blocks of the fit data) choose the
effects, test_signals are used for nothing but the reported held-out residual (roles.py).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..catalogue import STANDARD_FROM_DYNAMIC
from ..terms import simple_model
from . import choose, findings_check, fit, joints, reidentify, roles, trust
from .effects import Context, library
from .findings import describe, reported, with_values
from .judge import judge, simple_mse
from .notes import notes
from .options import Options
from .record import CandidateGain, Diagnosis, RecordingNote
from .refine import restricted
from .selection import forward, selection_mse, solve
from .settle import settle


def diagnose(robot, model, p, fit_signals, select_signals=None, options: Options = Options(),
             test=None) -> Diagnosis:
    p = np.asarray(p, dtype=float)
    s = model(STANDARD_FROM_DYNAMIC.name, p)
    n = robot.dof
    # 0. roles; a recording whose nominal residual exceeds its torques is conditioned again, or
    # trust.Unusable is raised (nothing claimed)
    fit_signals, select_signals, test = trust.checked_roles(model, s, fit_signals, select_signals, test)
    segments, split = roles.segments(model, s, fit_signals, select_signals, test, options.block_seconds)
    # Position- and velocity-dependent laws are known only over what the fit data cover.
    fit_q = np.vstack([seg.signals.q[seg.fit] for seg in segments if seg.fit.any()])
    fit_qd = np.vstack([seg.signals.qd[seg.fit] for seg in segments if seg.fit.any()])
    context = Context(model, robot, p, s, options.sign_velocity, (fit_q.min(axis=0), fit_q.max(axis=0)),
                      (fit_qd.min(axis=0), fit_qd.max(axis=0)))
    # 1. fit
    design = fit.build(context, library(context, options.effects), segments, n)

    def correlation(chosen, fitted):
        """The correlation time of what the chosen effects at the fitted values leave (the
        current context and design: the pipeline's own)."""
        return fit.correlation_time(fit.corrected(context, chosen, fitted.x, segments), design.weights)

    # 2. select
    selection = forward(design, options.min_gain, options.alpha)
    # 3. settle
    design, chosen, final, dropped, refused = settle(context, segments, design, selection.chosen, correlation, options)
    if chosen:
        # Once more with each joint weighted by what the effects leave of its residual: an
        # effect kept only to make up for another fitted with the nominal weights goes now.
        design, chosen, final, dropped_now, refused_now = settle(
            context, segments, fit.reweighted(design, final), chosen, correlation, options)
        dropped += dropped_now
        refused += refused_now
    # 4. choose, per joint: the effects, the simple model or both, all fitted on the fit samples
    # only and compared on the selection samples (joints.py). `selecting`: the segments with
    # the effects' torques at the values from the fit samples.
    selecting = fit.corrected(context, chosen, final.x, segments)
    simple = simple_model.fit(selecting)
    sel_before = selection_mse(design, [])
    sel_effects = selection_mse(design, chosen)
    sel_simple = simple_mse(selecting, simple, "select", n)
    if not design.select.count:
        modes = [joints.EFFECTS] * n
    elif select_signals:
        modes = joints.decide(context, selecting, chosen, final.x, simple, options.min_gain)
    else:
        modes = choose.on_folds(context, selecting, design, chosen, final, options)
    reid, consistent = None, None
    # Without the re-identification its cheap gate still says where the rigid body's columns
    # explain what the effects leave: the link parameters may be off there.
    links_hint, excitation = [], None
    run_reid = options.reidentify
    if run_reid is None and design.select.count:  # by default where the fit data excite the link parameters
        excitation = reidentify.excitation(model, selecting)
        run_reid = excitation <= reidentify.EXCITED
    if not run_reid and design.select.count:
        links_hint = reidentify.gate(model, selecting, [seg.residual - seg.correction for seg in selecting],
                                     options.min_gain)
    if run_reid and design.select.count:
        reid, consistent, modes = choose.reidentified(robot, model, p, context, selecting, chosen, final.x, simple,
                                                      modes, options.min_gain)
    described = [describe(robot, design, chosen, final, c, options.min_gain) for c in chosen]
    # The choice made, every sample of the fit recordings sets the values (selection blocks
    # included; separate selection recordings stay out of it, as test recordings do).
    fitting = selecting
    if not select_signals:
        fitting = [replace(seg, fit=seg.fit | seg.select) for seg in selecting]
        simple = simple_model.fit(fitting)
        # position laws now known over every fit sample's positions
        context = fit.ranged(context, fitting, chosen)
        if chosen:
            design, chosen = restricted(context, fitting, design, chosen)
            final = solve(design, chosen)
        if reid is not None:
            reid, consistent = choose.refit(robot, model, p, fitting, reid, consistent)
    fitted = fit.corrected(context, chosen, final.x, fitting)  # the effects at the final values
    tau_corr = fit.correlation_time(fitted, design.weights)
    described = with_values(described, design, chosen, final, tau_corr, robot)
    # 5. test: each joint's correction by the model it was given (the effects, the simple model, ...)
    judged_segments, completed = joints.apply(context, fitted, chosen, final.x, simple, modes, consistent)
    judged = judge(design, judged_segments, chosen, final, simple)
    # 6. report
    replaced = [j for j in range(n) if modes[j] in (joints.SIMPLE, joints.CONSISTENT)]
    selected, superseded = reported(chosen, described, replaced)
    selection_before = np.sqrt(sel_before).tolist()
    # findings outside their range: marked suspect
    selected, apart = findings_check.check(selected, selection_before, model, s, fit_signals)
    rms = {key: np.sqrt(x).tolist() for key, x in (("before", judged.before), ("after", judged.after),
                                                    ("effects", judged.effects), ("simple", judged.simple))}
    result = Diagnosis(
        robot=robot.name, joints=n, split=split, judged_on=judged.on, selected=selected,
        rms_before=rms["before"], rms_after=rms["after"], rms_effects=rms["effects"], rms_simple=rms["simple"],
        selection_before=selection_before, selection_after=np.sqrt(sel_effects).tolist(),
        selection_simple=np.sqrt(sel_simple).tolist(),
        simple_wins=[j + 1 for j in range(n) if modes[j] == joints.SIMPLE], simple_values=simple.values.tolist(),
        peak_before=judged.peak_before.tolist(), noise_rms=judged.noise.tolist(), where=judged.where,
        candidates=[CandidateGain(k, g) for k, g in sorted(selection.first_gains.items(), key=lambda kv: -kv[1])],
        steps=selection.steps, dropped=dropped, refused=refused, superseded=superseded, correlation_samples=tau_corr,
        segments=judged_segments, joint_models=modes, within_fit_speeds=judged.within_fit_speeds, completed=completed,
        consistent=None if reid is None else reidentify.finding(
            robot, reid, [j for j in range(n) if modes[j] == joints.CONSISTENT]),
        reidentified=reid,
        conditioning=[RecordingNote(sig.name, role, sig.note, sig.trim)
                      for role, group in (("fit", fit_signals), ("select", select_signals or []),
                                          ("test", test or [])) for sig in group])
    if links_hint:
        apart.append("the link parameters may be off: on joint(s) " + ", ".join(str(j + 1) for j in links_hint)
                     + " the rigid body's own columns explain what the effects leave on selection data, so the "
                     "effects found there may stand for wrong masses or inertias; --reidentify tries consistent link "
                     "parameters as an alternative (or identify them first: dyngen identify)"
                     + ("" if excitation is None else f"; not tried by default: the fit data excite the link parameters "
                        f"weakly (condition number {excitation:.3g} of their scaled columns, above "
                        f"{reidentify.EXCITED:g})"))
    return replace(result, warnings=notes(result, model, s, fit_signals, select_signals or [], test or [],
                                          judged.used) + apart)
