"""The diagnosis as text: a readable markdown report (report.md), JSON for scripts (diagnosis.json,
schema: docs/conventions.md, "Diagnosis JSON") and the terminal's summary lines."""

from __future__ import annotations

import json
from dataclasses import is_dataclass

import numpy as np

from .joints import EFFECTS, TIED
from .record import entry

SCHEMA_VERSION = 2


def to_json(d, sources: dict) -> str:
    """sources: {"params": file, "fit": [files], "select": [files], "test": [files], "conditioning": text}."""
    doc = {
        "schema": SCHEMA_VERSION, "robot": d.robot, "joints": d.joints, "split": d.split, **sources,
        "judged_on": d.judged_on, "rms_before": d.rms_before, "rms_after": d.rms_after,
        "rms_effects": d.rms_effects, "rms_simple": d.rms_simple,
        "selection_rms_before": d.selection_before, "selection_rms_after": d.selection_after,
        "selection_rms_simple": d.selection_simple, "simple_wins": d.simple_wins, "simple_values": d.simple_values,
        "peak_before": d.peak_before, "noise_rms": d.noise_rms, "correlation_samples": d.correlation_samples,
        "selected": d.selected, "superseded": d.superseded, "unstable": d.unstable, "refused": d.refused, "where": d.where,
        "candidates": d.candidates, "steps": d.steps, "dropped": d.dropped, "warnings": d.warnings,
        "recordings": d.conditioning, "joint_models": d.joint_models,
        "completed": {str(j): values for j, values in d.completed.items()},
        "link_parameters_off": d.consistent, "within_fit_speeds": d.within_fit_speeds, "control": d.control,
    }
    return json.dumps(_plain(doc), indent=1) + "\n"


def _plain(x):
    if is_dataclass(x):  # the findings' types (record.py): their diagnosis.json entries
        return _plain(entry(x))
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return None if not np.isfinite(x) else float(x)
    if isinstance(x, np.integer):
        return int(x)
    return x


def _value_text(e) -> str:
    parts = [f"{name} not identifiable" if value is None else f"{name} = {value:.4g} +- {e.std[name]:.2g} {e.units[name]}"
             for name, value in e.values.items()]
    text = ", ".join(parts)
    if len(parts) > 4:  # the coefficient errors, the payload, the ripple: the largest ones only
        shown = sorted(((abs(v / e.std[n]) if e.std[n] else 0, n) for n, v in e.values.items()
                        if v is not None), reverse=True)[:3]
        text = f"{len(parts)} values; most significant: " + ", ".join(
            f"{n} = {e.values[n]:.3g} +- {e.std[n]:.2g}" for _, n in shown)
    for key, value in e.variant.items():
        shown = f"({', '.join(f'{x:.3g}' for x in value)})" if isinstance(value, (list, tuple)) else f"{value:.3g}"
        text += f" (at {key} = {shown})"
    derived = e.derived
    if "tilt_deg" in derived:
        (a1, a2), (s1, s2), (u1, u2) = derived["tilt_deg"], derived["tilt_std_deg"], derived["tilt_towards"]
        text += f" (gravity turned {a1:.2f} +- {s1:.2f} deg towards {u1} and {a2:.2f} +- {s2:.2f} deg towards {u2})"
    if "relative" in derived:
        text += f" (gravity torques scaled by {1 + derived['relative']:.4f})"
    if "amplitude_Nm" in derived and derived.get("separable", True):
        text += " (amplitudes of harmonics 1, 2, 3 of the joint position: " + \
                ", ".join(f"{a:.3g}" for a in derived["amplitude_Nm"]) + " Nm)"
    elif "amplitude_Nm" in derived:
        text = (f"a torque of {derived['torque_rms_Nm']:.3g} Nm RMS depending on the joint's position; its harmonics "
                "are not separable over the positions covered (values flagged, not findings)")
    if "dt_ms" in derived:
        text += f" ({derived['dt_ms']:.2f} +- {derived['dt_std_ms']:.2f} ms)"
    if "mass_kg" in derived:
        com = ", ".join("?" if c is None else f"{c:.3g}" for c in derived["com_m"])
        text += f" (payload mass {derived['mass_kg']:.3g} kg, centre of mass ({com}) m in the last link's frame)"
    if e.suspect:
        text += " **suspect**"
    return text


def _named(e) -> str:
    return e.effect + (f" on joint(s) {', '.join(map(str, e.joints))}" if e.joints else "")


def _row(label, values) -> str:
    return f"| {label} | " + " | ".join(f"{x:.3f}" for x in values) + " |"


def markdown(d, sources: dict) -> str:
    head = " | ".join(f"J{j + 1}" for j in range(d.joints))
    rule = "|---|" + "---:|" * d.joints
    test = d.judged_on == "test"
    lines = [f"# Diagnosis of {d.robot}", "",
             f"Model parameters: {sources.get('params')}. Fit on: {', '.join(sources.get('fit', []))}. "
             f"Selection: {', '.join(sources.get('select') or []) or d.split}. "
             f"Test (held out, used for nothing else): {', '.join(sources.get('test') or []) or 'none'}.", ""]
    lines += ["Conditioning:", ""] + [f"- {c.recording} ({c.role}): {c.note}; {c.trimmed_samples} samples "
                                      "trimmed at each end" for c in d.conditioning] + [""]
    if d.control:
        lines += [f"Control run: {d.control}.", ""]
    if d.warnings:
        lines += ["## Warnings", ""] + [f"- {w}" for w in d.warnings] + [""]
    lines += [f"## {'Test' if test else 'Selection'} residual (measured - model) per joint [Nm or N]", "",
              ("On the test recordings, which played no part in fitting or choosing the effects." if test else
               "**No test data**: these are the selection data, which chose the effects. Not a held-out figure."),
              "", f"| | {head} |", rule,
              _row("RMS, nominal model", d.rms_before),
              _row("RMS, final model (effects; simple model where it won or tied)", d.rms_after),
              _row("RMS, selected effects alone", d.rms_effects),
              _row("RMS, simple model b + Fc tanh(qd/0.02) + Fv qd (fit data)", d.rms_simple),
              _row("peak, nominal model", d.peak_before),
              _row("white-noise estimate", d.noise_rms), ""]
    worse = worse_than_simple(d)
    if worse:
        lines += [f"The final model is {worse}.", ""]
    w = d.within_fit_speeds
    if w and any(x > 0 for x in w["share_beyond"]):
        dash = lambda xs: " | ".join("-" if x is None else f"{x:.3f}" for x in xs)  # noqa: E731
        lines += ["At the joint velocities the fit data covered (beyond them velocity laws are extrapolated, "
                  "and the selection data could not judge them):", "", f"| | {head} |", rule,
                  "| share of samples beyond | " + " | ".join(f"{x:.0%}" for x in w["share_beyond"]) + " |",
                  f"| RMS, final model, within | {dash(w['rms_after'])} |",
                  f"| RMS, simple model, within | {dash(w['rms_simple'])} |", ""]
    if test:
        lines += ["Selection data (they chose the effects; not held out):", "", f"| | {head} |", rule,
                  _row("RMS, nominal model", d.selection_before),
                  _row("RMS, selected effects", d.selection_after),
                  _row("RMS, simple model", d.selection_simple), ""]
    lines += [f"## Where ({'test' if test else 'selection'} data, nominal model)", "",
              "| joint | RMS | mean | where it stands out | RMS there | share of samples | RMS after |",
              "|---|---:|---:|---|---:|---:|---:|"]
    for w in d.where:
        worst = w["worst_phase"]
        there = w["phases"].get(worst, {}) if worst else {}
        lines.append(f"| {w['joint']} | {w['rms']:.3f} | {w['mean']:+.3f} | {worst or '-'} "
                     f"({w['worst_ratio']:.2f}x) | {there.get('rms', float('nan')):.3f} | "
                     f"{there.get('share', float('nan')):.0%} | {there.get('rms_after', float('nan')):.3f} |")
    lines += ["", "## Which effects (fitted on fit data, chosen on selection data)", ""]
    if not d.selected:
        lines += ["No effect improves the selection residual significantly: nothing is claimed.", ""]
    else:
        lines += ["| effect | joints | fitted values (+- std) | selection gain | selection RMS without -> with, "
                  "on its joints |", "|---|---|---|---:|---|"]
        for e in d.selected:
            joints = ", ".join(map(str, e.joints)) or "-"
            change = ", ".join(f"J{j}: {e.rms_before[j - 1]:.3f} -> {e.rms_after[j - 1]:.3f}" for j in e.joints)
            lines.append(f"| {e.effect} | {joints} | {_value_text(e)} | {e.selection_gain:.3f} | {change} |")
        lines += ["", "Selection gain: the decrease of the selection data's mean square residual relative to its value "
                  "without this effect (all other selected effects kept), on its joint (per-joint effects) or summed "
                  "over joints (arm-wide effects). Standard deviations "
                  f"are scaled for the residual's correlation in time ({d.correlation_samples:.0f} samples).", ""]
    said = (  # (a paragraph, the list it names; nothing is said of an empty list)
        ("Not kept (another model did better on these joints' selection data): {}.",
         ", ".join(_named(e) for e in d.superseded if not e.suspect)),  # suspect: not told apart from wrong links
        ("Not claimed, not told apart from the link parameters being off (see the warnings): {}.",
         ", ".join(_named(e) for e in d.superseded if e.suspect)),
        ("Unstable across blocks, so not claimed (kept in the model): {}.",
         "; ".join(f"{_named(u.finding)}: {u.reason}" for u in d.unstable)),
        ("On joint(s) {} the simple model predicts the torque: on the selection data the effects acting there did not "
         "beat it by the margin a value must gain. Findings there stay findings; the data cannot tell the two apart, "
         "and beyond the fit data they may extrapolate differently.",
         ", ".join(str(j + 1) for j, m in enumerate(d.joint_models) if m == TIED)),
        ("Refused as physically impossible once fitted: {}.", ", ".join(r.candidate for r in d.refused)),
        ("Selected at first, then dropped as not significant: {}.", ", ".join(d.dropped)))
    lines += [line for text, names in said if names for line in (text.format(names), "")]
    if d.consistent:  # what they are and why: the warning "link parameters off" (notes.py)
        lines += ["## Link parameters off", ""]
        if d.reidentified is not None:
            from types import SimpleNamespace

            from ..identification.consistent_output import summary_lines as consistent_summary

            lines += ["```"] + consistent_summary(SimpleNamespace(name=d.robot, dof=d.joints), d.reidentified) \
                + ["```", ""]
    lines += ["## Candidates tried alone (selection gain; Stribeck beside its Coulomb term)", "",
              ", ".join(f"{c.candidate} {c.selection_gain:+.3f}" for c in d.candidates[:15]), ""]
    return "\n".join(lines)


def worse_than_simple(d) -> str:
    """Joints where the final model ends above the simple model, with both figures (also within the fit
    speeds); "" if none."""
    worse = [j for j in range(d.joints) if d.rms_after[j] > d.rms_simple[j]]
    if not worse:
        return ""
    text = "worse than the simple model on joint(s) " + ", ".join(
        f"{j + 1} ({d.rms_after[j]:.3f} vs {d.rms_simple[j]:.3f})" for j in worse)
    w = d.within_fit_speeds
    inside = [j for j in worse if w and w["rms_after"][j] is not None and w["share_beyond"][j] > 0]
    if inside:
        text += "; at the joint velocities the fit data covered " + ", ".join(
            f"{w['rms_after'][j]:.3f} vs {w['rms_simple'][j]:.3f}" for j in inside) + \
            " (beyond them velocity laws are extrapolated)"
    return text


def summary_lines(d) -> list[str]:
    where = "test" if d.judged_on == "test" else "selection (no test data)"
    out = [f"  {where} RMS per joint: nominal {' '.join(f'{x:.3f}' for x in d.rms_before)}",
           f"  {' ' * len(where)}               after   {' '.join(f'{x:.3f}' for x in d.rms_after)}",
           f"  {' ' * len(where)}        simple model   {' '.join(f'{x:.3f}' for x in d.rms_simple)}"]
    worse = worse_than_simple(d)
    if worse:
        out.append(f"  {worse}")
    models = ", ".join(f"J{j + 1} {m}" for j, m in enumerate(d.joint_models) if m != EFFECTS)
    if models:
        out.append(f"  per joint model where not the effects alone: {models}")
    if not d.selected:
        out.append("  no significant unmodelled effect")
    for e in d.selected:
        joints = ",".join(map(str, e.joints)) or "-"
        out.append(f"  {e.effect:<12} joints {joints:<14} gain {e.selection_gain:.3f}  {_value_text(e)}")
    out += [f"  unstable across blocks, not claimed: {_named(u.finding)}" for u in d.unstable]
    if d.control:
        out.append(f"  control: {d.control}")
    out += [f"  warning: {w}" for w in d.warnings]
    return out
