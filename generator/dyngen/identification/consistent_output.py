"""What `dyngen identify` writes for the consistent identification: the YAML (`links:` as
`diagnose --params` and the exporters read them, friction per joint, the `identified:` block),
a Markdown table, and the summary lines printed."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..extraction.report import links_yaml
from ..terms import simple_model, tilt
from .columns import coulomb_matrix


@dataclass
class Consistent:
    """The result: full link parameters, friction per joint, and the statistics of the fit."""

    p: np.ndarray  # dynamic parameters (10N), physically consistent
    pi: np.ndarray  # full base coefficients of p
    names: list  # base coefficient expressions (standard parameters)
    friction: dict  # kind -> (N,) values (nan where the column is not in the model); "tilt": (a1, a2)
    smoothing: np.ndarray  # (N,) vs_j [rad/s]
    sigma: np.ndarray  # (N,) per-joint noise estimate used as weight [Nm]
    ols: object  # least_squares.Estimate of the unconstrained weighted fit (coefficients, then friction)
    column_names: list  # names of the OLS columns
    residual_rms: np.ndarray  # (N,) RMS of the consistent model's residual on the fit data
    ols_residual_rms: np.ndarray  # (N,) the same for the unconstrained fit
    lambda_min: np.ndarray  # (N,) consistency margin of each link
    regularisation: float
    selection: list  # (lambda, held-out weighted mean square) tried
    dropped_armature: list = field(default_factory=list)  # joints whose rotor inertia the body carries
    at_bounds: list = field(default_factory=list)  # parameter names pinned at a bound
    tilt_model: tuple | None = None  # (robot, parameters) the tilt's torques are evaluated with
    dropped_columns: list = field(default_factory=list)  # columns the data cannot separate, or refused
    lags: np.ndarray | None = None  # (N,) lag of the Coulomb term behind the velocity [s]
    groups: list = field(default_factory=list)  # (group, joint or None, gain, its se, kept) decided on held-out data
    notes: list = field(default_factory=list)  # what a user must know (e.g. a tilt refused)
    # joints the simple model predicts instead (identification/sanity.py): {"joints": 0-based,
    # "values": (N, 3) b, Fc, Fv, "prior": the prior's 10N parameters, "standard": its standard ones}
    simple: dict | None = None

    def joint_dynamics(self) -> list:
        """Per joint {"damping", "friction", "armature"} for the URDF/MJCF writers (a negative Fv left out)."""
        f = self.friction
        return [{"damping": max(_nz(f["viscous"][j]), 0.0), "friction": _nz(f["coulomb"][j]),
                 "armature": _nz(f["armature"][j])} for j in range(len(self.sigma))]

    def tilt_deg(self) -> float:
        return 0.0 if self.tilt_model is None else tilt.angle_deg(tilt.gravity_of(self.tilt_model[0]), self.friction["tilt"])

    def predict(self, model, signals) -> np.ndarray:
        """Torques (T, N) of this model on signals (Coulomb through the recording's filter, as in the fit)."""
        f = {k: np.nan_to_num(v) for k, v in self.friction.items()}
        out = model.batch("regressor", signals.q, signals.qd, signals.qdd) @ self.pi
        if np.any(f["coulomb"]):
            out = out + f["coulomb"] * coulomb_matrix(signals, self.smoothing, self.lags)
        out = out + (f["viscous"] * signals.qd + f["offset"] + f["armature"] * signals.qdd
                     + f["ripple_cos"] * np.cos(signals.q) + f["ripple_sin"] * np.sin(signals.q))
        if self.tilt_model is not None:
            out = out + tilt.torque(*self.tilt_model, signals.q, tilt.gravity_of(self.tilt_model[0]), self.friction["tilt"])
        if self.simple:  # the prior's rigid body + b + Fc tanh(qd / 0.02) + Fv qd there
            j = list(self.simple["joints"])
            rigid = model.batch("rnea", signals.q, signals.qd, signals.qdd, self.simple["standard"])
            out[:, j] = (rigid + np.einsum("tjk,jk->tj", simple_model.columns(signals), self.simple["values"]))[:, j]
        return out


def _nz(x) -> float:
    return 0.0 if not np.isfinite(x) else float(x)


def _f(x) -> str:
    return "null" if not np.isfinite(x) else f"{float(x):.6g}"


def consistent_yaml(robot, c, sources: list[str], conditioning: str) -> str:
    ols = c.ols
    lines = [
        f"# {robot.name}: physically consistent identification by dyngen from {', '.join(sources)}.",
        f"# Conditioning: {conditioning}. Rows weighted by 1 / sigma_j (per-joint noise below); "
        f"regularisation toward the prior: {c.regularisation:g}.",
        "# Torque model: Y(q, qd, qdd) pi(links) + Fc tanh(qd / vs) + Fv qd + offset + Ia qdd"
        + (" + ripple a cos q + b sin q" if np.any(np.isfinite(c.friction["ripple_cos"])) else "")
        + (" + the torque of gravity turned by the base tilt" if c.tilt_model is not None else "")
        + "; Fc >= 0, Ia >= 0, Fv >= 0 (or Fc + Fv v_max >= 0 where friction falls with speed).",
        "# std: of the unconstrained weighted least squares of the same columns, a sandwich estimate over blocks of "
        "the residual's correlation time (holds for correlated residuals).",
        f"robot: {robot.name}",
        "links:",
        links_yaml(c.p).rstrip("\n"),
        "friction:   # per joint; Coulomb Fc tanh(qd(t - lag) / vs) [Nm, s, rad/s], viscous Fv [Nm s/rad], "
        "offset [Nm], rotor inertia Ia [kg m^2] (null: carried by the rigid body), ripple [a, b]: "
        "a cos q + b sin q [Nm], sigma: noise [Nm]"]
    k = {name: i for i, name in enumerate(c.column_names)}
    for j in range(robot.dof):
        def std(kind):
            i = k.get(f"{kind} j{j + 1}")
            return _f(ols.std[i]) if i is not None else "null"
        lines.append(f"  - {{Fc: {_f(c.friction['coulomb'][j])}, vs: {_f(c.smoothing[j])}, Fv: {_f(c.friction['viscous'][j])}, "
                     f"offset: {_f(c.friction['offset'][j])}, Ia: {_f(c.friction['armature'][j])}, "
                     f"lag: {_f(c.lags[j] if c.lags is not None else 0.0)}, "
                     f"ripple: [{_f(c.friction['ripple_cos'][j])}, {_f(c.friction['ripple_sin'][j])}], "
                     f"sigma: {_f(c.sigma[j])}}}   # joint {j + 1}; std Fc {std('coulomb')}, Fv {std('viscous')}, "
                     f"offset {std('offset')}, Ia {std('armature')}")
    if c.simple:
        lines += ["simple_model:   # joints the simple model predicted the --select recordings better on; there "
                  "tau_j = Y_j(q, qd, qdd) pi(prior_links) + b + Fc tanh(qd / 0.02) + Fv qd [Nm, Nm, Nm s/rad] "
                  "(the URDF and MJCF carry the links and friction above)", "  joints:"]
        for j in c.simple["joints"]:
            b, fc, fv = c.simple["values"][j]
            lines.append(f"    - {{joint: {j + 1}, b: {_f(b)}, Fc: {_f(fc)}, Fv: {_f(fv)}}}")
        lines += ["  prior_links:", *("  " + x for x in links_yaml(c.simple["prior"]).rstrip("\n").splitlines())]
    if c.tilt_model is not None:
        dg = tilt_change(c)
        lines.append(f"tilt: {{dg: [{_f(dg[0])}, {_f(dg[1])}, {_f(dg[2])}], angle_deg: {_f(c.tilt_deg())}}}   "
                     "# m/s^2: the change of the gravity vector in the base frame (a rotation: its size is kept)")
    lines.append(f"identified:\n  full:   # base coefficients of the links above; condition number {ols.condition:.3g} "
                 f"(weighted, with the friction columns; columns scaled {ols.scaled_condition:.3g})")
    for i, name in enumerate(c.names):
        note = "not excited by the data: set by the prior and consistency" if i in ols.unexcited \
            else f"std {ols.std[i]:.3g}, unconstrained fit {ols.values[i]:.6g}"
        lines.append(f'    - {{coefficient: "{name}", value: {float(c.pi[i])!r}}}   # {note}')
    return "\n".join(lines) + "\n"


def tilt_change(c) -> np.ndarray:
    """The tilt's change of the gravity vector in the base frame [m/s^2]."""
    g = tilt.gravity_of(c.tilt_model[0])
    return tilt.directions(g).T @ tilt.change(g, c.friction["tilt"])


def consistent_table(c) -> str:
    """Markdown: per base coefficient the consistent value, the unconstrained one and its std."""
    return "\n".join(["| coefficient | consistent | unconstrained | std | excited |", "|---|---:|---:|---:|---|"]
                     + [f"| {name} | {c.pi[i]:.6g} | {c.ols.values[i]:.6g} | {c.ols.std[i]:.3g} | "
                        f"{'no' if i in c.ols.unexcited else 'yes'} |" for i, name in enumerate(c.names)])


def summary_lines(robot, c) -> list[str]:
    n = robot.dof
    out = [f"{robot.name}: physically consistent identification, {len(c.names)} base coefficients + friction "
           f"from {c.ols.rows} equations; condition number {c.ols.condition:.3g} (columns scaled "
           f"{c.ols.scaled_condition:.3g})"]
    out.append("  per-joint noise sigma used as weight [Nm]: " + ", ".join(f"{x:.3g}" for x in c.sigma))
    out.append("  residual RMS on the fit data [Nm], consistent: " + ", ".join(f"{x:.3g}" for x in c.residual_rms)
               + "; unconstrained: " + ", ".join(f"{x:.3g}" for x in c.ols_residual_rms))
    if c.selection:
        out.append("  regularisation toward the prior chosen on held-out data: " + ", ".join(
            f"{lam:g}{'*' if lam == c.regularisation else ''} ({score:.4g})" for lam, score in c.selection))
    else:
        out.append(f"  regularisation toward the prior: {c.regularisation:g}")
    out.append("  friction: " + "; ".join(
        f"j{j + 1} Fc {c.friction['coulomb'][j]:.3g} Fv {c.friction['viscous'][j]:.3g} b {c.friction['offset'][j]:+.3g}"
        + (f" Ia {c.friction['armature'][j]:.3g}" if np.isfinite(c.friction['armature'][j]) else "")
        for j in range(n)))
    if c.tilt_model is not None:
        dg = tilt_change(c)
        out.append(f"  base tilt: {c.tilt_deg():.2f} deg (gravity changed by ({dg[0]:+.3g}, {dg[1]:+.3g}, {dg[2]:+.2g}) m/s^2 "
                   "in the base frame)")
    if c.groups:
        out.append("  optional parts chosen on held-out stretches of the fit data (kept where they gain more than a "
                   "standard error): " + groups_text(c.groups))
    out.append("  every link consistent: lambda_min(tr(I)/2 E - I) = " + ", ".join(f"{x:.2e}" for x in c.lambda_min))
    if c.ols.unexcited:
        out.append(f"  {len(c.ols.unexcited)} coefficient(s) not excited by the data (set by the prior and "
                   "consistency): " + ", ".join(c.column_names[i] for i in c.ols.unexcited))
    if c.dropped_columns:
        out.append("  left out (the data cannot tell them from the rest of the model): " + ", ".join(c.dropped_columns))
    if c.at_bounds:
        out.append(f"  parameters at a bound of the YAML: {', '.join(c.at_bounds)}")
    negative = [j + 1 for j in range(n) if c.friction["viscous"][j] < 0]
    if negative:
        out.append(f"  viscous friction below 0 on joint(s) {', '.join(map(str, negative))} (friction falling with "
                   "speed, chosen on held-out data; it still opposes motion up to the velocity limit); left out of the "
                   "MJCF/URDF damping")
    out += [f"  note: {note}" for note in c.notes]
    return out


def groups_text(groups) -> str:
    """e.g. "base tilt kept; position ripple on joint(s) 5, 7 (not 1, 3, 4, 6); ..."."""
    parts = []
    title = {"tilt": "base tilt", "ripple": "position ripple", "falling": "friction allowed to fall with speed"}
    for name in dict.fromkeys(g[0] for g in groups):
        rows = [g for g in groups if g[0] == name]
        if rows[0][1] is None:
            parts.append(f"{title.get(name, name)} {'kept' if rows[0][4] else 'left out'}")
            continue
        kept = [str(g[1]) for g in rows if g[4]]
        out = [str(g[1]) for g in rows if not g[4]]
        parts.append(f"{title.get(name, name)} on joint(s) {', '.join(kept) or 'none'}"
                     + (f" (not {', '.join(out)})" if kept and out else ""))
    return "; ".join(parts)
