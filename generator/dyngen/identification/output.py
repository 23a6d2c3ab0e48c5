"""The identified coefficients as the YAML `identified:` block that `dyngen extract` reads
(docs/conventions.md), and as a short table."""

from __future__ import annotations

import numpy as np


def identified_yaml(robot_name: str, estimates: dict, sources: list[str], conditioning: str) -> str:
    """estimates: kind -> Estimate. Coefficients are written as their standard-parameter
    expressions (dyngen's base coefficients), which `identified:` accepts as they are."""
    lines = [f"# Base coefficients of {robot_name} identified by dyngen (least squares, eq. 11) from "
             f"{', '.join(sources)}.",
             f"# Conditioning: {conditioning}.",
             "# Paste the `identified:` block into the robot YAML (or merge it) and run `dyngen extract`.",
             "# std: standard deviation from the residual variance and (A^T A)^-1 (uncorrelated residuals assumed).",
             "identified:"]
    for kind, est in estimates.items():
        lines.append(f"  {kind}:   # condition number {est.condition:.3g} (columns scaled: "
                     f"{est.scaled_condition:.3g}), residual RMS {est.residual_rms:.4g}, {est.rows} rows")
        for k, (name, value, std) in enumerate(zip(est.names, est.values, est.std)):
            note = "not excited by the data: value not determined" if k in est.unexcited else f"std {std:.3g}"
            lines.append(f'    - {{coefficient: "{name}", value: {float(value)!r}}}   # {note}')
    return "\n".join(lines) + "\n"


def summary_table(kind: str, est) -> str:
    """Markdown: one row per coefficient with value, std and relative std."""
    rows = [f"| {kind} coefficient | value | std | std / abs(value) |", "|---|---:|---:|---:|"]
    for k, (name, value, std) in enumerate(zip(est.names, est.values, est.std)):
        rel = std / abs(value) if value != 0 else np.inf
        flag = " (not excited)" if k in est.unexcited else ""
        rows.append(f"| {name}{flag} | {value:.6g} | {std:.3g} | {rel:.2g} |")
    return "\n".join(rows)
