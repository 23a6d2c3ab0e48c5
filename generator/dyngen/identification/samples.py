"""Least squares of eq. (11) from conditioned recordings: kind "gravity" Y_g(q) pi_g = tau (static
poses, or the FRI's g(q), eq. 9), "inertia" Y_m(q) pi_m = the stacked M11, M12, ... columns (the
FRI's M(q), eq. 10), "full" Y(q, qd, qdd) pi = tau; and the identified coefficients as the YAML
`identified:` block that `dyngen extract` reads (docs/conventions.md) and as a short table."""

from __future__ import annotations

import numpy as np

from ..catalogue import REGRESSORS
from ..errors import InputError
from .least_squares import Estimate, fit_factor
from .triangular import Triangular

REGRESSOR = {kind: f.name for kind, f in REGRESSORS.items()}


def stacked_inertia_columns(manifest) -> list[str]:
    return list(manifest["stacked_inertia_order"])


def regressor_rows(model, kind: str, q, qd, qdd, tau, extra) -> tuple[np.ndarray, np.ndarray]:
    """(Y (T, m, c), b (T, m)): the regressor rows and measurements of T samples, m rows each."""
    if kind == "gravity":
        return model.batch(REGRESSOR[kind], q), tau
    if kind == "inertia":
        return model.batch(REGRESSOR[kind], q), np.column_stack([extra[c] for c in stacked_inertia_columns(model.manifest)])
    return model.batch(REGRESSOR[kind], q, qd, qdd), tau


def identify(model, signals: list, kind: str) -> Estimate:
    """The least-squares fit of every sample that is data (Signals.inner), folded into per-joint triangular
    factors as --ols folds blocks."""
    if kind not in REGRESSOR:
        raise ValueError(f"unknown kind {kind!r}; expected one of {', '.join(REGRESSOR)}")
    names = [e["standard"] for e in model.manifest["coefficients"][kind]["expressions"]]
    files = ", ".join(s.name for s in signals)
    factors = None
    for s in signals:
        if kind == "inertia":
            missing = [c for c in stacked_inertia_columns(model.manifest) if c not in s.extra]
            if missing:
                raise InputError(s.name, "line 1 (header)", f"missing column(s) {', '.join(missing)} "
                                 "(stacked inertia matrix, needed for --kind inertia)")
        keep = s.inner()  # not the filter's start-up at the ends
        Y, b = regressor_rows(model, kind, s.q[keep], s.qd[keep], s.qdd[keep], None if s.tau is None else s.tau[keep],
                              {k: v[keep] for k, v in s.extra.items()})
        factors = factors or Triangular(Y.shape[-1], Y.shape[1])
        factors.add(Y, b)
    rows = int(factors.rows.sum())
    if rows <= factors.c:
        raise InputError(files, "", f"under-determined: {rows} equations for {factors.c} {kind} "
                         f"coefficients; record at least {factors.c // factors.dof + 1} samples (many more, "
                         "on an exciting trajectory, for a usable estimate)")
    try:
        return fit_factor(factors.factor(), rows, names)
    except np.linalg.LinAlgError as err:
        raise InputError(files, "", f"least squares failed ({err}); check the recordings for extreme values") from None


def identified_yaml(robot_name: str, estimates: dict, sources: list[str], conditioning: str) -> str:
    """estimates: kind -> Estimate; coefficients written as standard-parameter expressions."""
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
