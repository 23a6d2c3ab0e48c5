"""The diagnosis as a readable markdown report and as JSON for scripts (schema:
docs/conventions.md, "Diagnosis JSON")."""

from __future__ import annotations

import json

import numpy as np

SCHEMA_VERSION = 1


def to_json(d, sources: dict) -> str:
    """sources: {"params": file, "fit": [files], "holdout": [files], "conditioning": text}."""
    doc = {
        "schema": SCHEMA_VERSION, "robot": d.robot, "joints": d.joints, "split": d.split, **sources,
        "rms_before": d.rms_before, "rms_after": d.rms_after, "peak_before": d.peak_before,
        "noise_rms": d.noise_rms, "correlation_samples": d.correlation_samples,
        "selected": d.selected, "where": d.where, "candidates": d.candidates, "steps": d.steps,
        "dropped": d.dropped,
    }
    return json.dumps(_plain(doc), indent=1) + "\n"


def _plain(x):
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
    parts = []
    for name, value in e["values"].items():
        unit = e["units"][name]
        if value is None:
            parts.append(f"{name} not identifiable")
        else:
            parts.append(f"{name} = {value:.4g} +- {e['std'][name]:.2g} {unit}")
    text = ", ".join(parts)
    if len(parts) > 4:  # the 43 coefficient errors or the payload: the largest ones only
        shown = sorted(((abs(v / e["std"][n]) if e["std"][n] else 0, n) for n, v in e["values"].items()
                        if v is not None), reverse=True)[:3]
        text = f"{len(parts)} values; most significant: " + ", ".join(
            f"{n} = {e['values'][n]:.3g} +- {e['std'][n]:.2g}" for _, n in shown)
    for key, value in e.get("variant", {}).items():
        text += f" (at {key} = {value:g})"
    derived = e.get("derived") or {}
    if "tilt_deg" in derived:
        text += " (tilt {:.2f} +- {:.2f} deg, {:.2f} +- {:.2f} deg)".format(
            derived["tilt_deg"][0], derived["tilt_std_deg"][0], derived["tilt_deg"][1], derived["tilt_std_deg"][1])
    if "dt_ms" in derived:
        text += f" ({derived['dt_ms']:.2f} +- {derived['dt_std_ms']:.2f} ms)"
    if "mass_kg" in derived:
        text += f" (payload mass {derived['mass_kg']:.3g} kg)"
    return text


def markdown(d, sources: dict) -> str:
    n = d.joints
    head = " | ".join(f"J{j + 1}" for j in range(n))
    rule = "|---|" + "---:|" * n
    lines = [f"# Diagnosis of {d.robot}", "",
             f"Model parameters: {sources.get('params')}. Fit on: {', '.join(sources.get('fit', []))}. "
             f"Held out: {', '.join(sources.get('holdout') or []) or d.split}. "
             f"Conditioning: {sources.get('conditioning')}.", "",
             "## Held-out residual (measured - model) per joint [Nm or N]", "",
             f"| | {head} |", rule,
             "| RMS, nominal model | " + " | ".join(f"{x:.3f}" for x in d.rms_before) + " |",
             "| RMS, with the selected effects | " + " | ".join(f"{x:.3f}" for x in d.rms_after) + " |",
             "| peak, nominal model | " + " | ".join(f"{x:.3f}" for x in d.peak_before) + " |",
             "| white-noise estimate | " + " | ".join(f"{x:.3f}" for x in d.noise_rms) + " |", ""]
    lines += ["## Where (nominal model, held-out data)", "",
              "| joint | RMS | mean | where it stands out | RMS there | share of samples | RMS after |",
              "|---|---:|---:|---|---:|---:|---:|"]
    for w in d.where:
        worst = w["worst_phase"]
        there = w["phases"].get(worst, {}) if worst else {}
        lines.append(f"| {w['joint']} | {w['rms']:.3f} | {w['mean']:+.3f} | {worst or '-'} "
                     f"({w['worst_ratio']:.2f}x) | {there.get('rms', float('nan')):.3f} | "
                     f"{there.get('share', float('nan')):.0%} | {there.get('rms_after', float('nan')):.3f} |")
    lines += ["", "## Which effects (selected on held-out data)", ""]
    if not d.selected:
        lines += ["No effect improves the held-out residual significantly: nothing is claimed.", ""]
    else:
        lines += ["| effect | joints | fitted values (+- std) | held-out gain | held-out RMS without -> with, "
                  "on its joints |", "|---|---|---|---:|---|"]
        for e in d.selected:
            joints = ", ".join(map(str, e["joints"])) or "-"
            change = ", ".join(f"J{j}: {e['rms_before'][j - 1]:.3f} -> {e['rms_after'][j - 1]:.3f}" for j in e["joints"])
            lines.append(f"| {e['effect']} | {joints} | {_value_text(e)} | {e['heldout_gain']:.3f} | {change} |")
        lines += ["", "Held-out gain: the decrease of the held-out mean square residual relative to its value without "
                  "this effect (all other selected effects kept), on its joint (per-joint effects) or summed over "
                  "joints (arm-wide effects). Standard deviations "
                  f"are scaled for the residual's correlation in time ({d.correlation_samples:.0f} samples).", ""]
    if d.dropped:
        lines += [f"Selected at first, then dropped as not significant: {', '.join(d.dropped)}.", ""]
    lines += ["## Candidates tried alone (held-out gain)", "",
              ", ".join(f"{c['candidate']} {c['heldout_gain']:+.3f}" for c in d.candidates[:15]), ""]
    return "\n".join(lines)


def summary_lines(d) -> list[str]:
    """A short table for the terminal."""
    out = [f"  held-out RMS per joint: nominal {' '.join(f'{x:.3f}' for x in d.rms_before)}",
           f"                         after   {' '.join(f'{x:.3f}' for x in d.rms_after)}"]
    if not d.selected:
        out.append("  no significant unmodelled effect")
    for e in d.selected:
        joints = ",".join(map(str, e["joints"])) or "-"
        out.append(f"  {e['effect']:<12} joints {joints:<14} gain {e['heldout_gain']:.3f}  {_value_text(e)}")
    return out
