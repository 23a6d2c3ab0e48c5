"""Identification sanity: every identified value inside its physical range, every search
that ended at its grid's edge named, and the result's prediction beside the simple model's.

    lines, table = check(robot, model, result, fit, select, prior)

Ranges (warnings, the values are kept and written):
  - rotor inertia: at most ROTOR_RATIO times the arm's own inertia about the joint (the median
    of M_jj over the fit data; a reflected rotor inertia is comparable to it, not an order of
    magnitude above: 24 x the true value came out on a light wrist joint whose data could not
    separate it from an offset and a lag);
  - an offset or a ripple amplitude: at most the RMS of the measured torque on its joint (a
    constant larger than the torque it sits in is a term making up for another);
  - the Coulomb lag and smoothing: a choice at the last value of its grid is a bound, not a
    finding (consistent.LAG_GRID, SMOOTHING_GRID).
The simple model (terms/simple_model.py: the prior's residual fitted per joint by b + Fc
tanh(qd / 0.02) + Fv qd on the fit data) and the identified model are both judged on the
--select recordings, which neither fitted; a joint where the simple model predicts better is
named, with the advice to use the simple model there (the diagnosis does so itself:
diagnosis/joints.py). Without --select nothing held out exists, and the table says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..catalogue import RNEA, STANDARD_FROM_DYNAMIC
from ..terms import simple_model as baseline
from .consistent import LAG_GRID, SMOOTHING_GRID

ROTOR_RATIO = 10.0
TIE = 1.0  # the simple model is preferred where its held-out RMS is below TIE x the identified model's


@dataclass
class _Segment:  # what baseline.fit reads
    signals: object
    residual: np.ndarray
    fit: np.ndarray


def _inertia_about_joints(model, p, signals) -> np.ndarray:
    s = model(STANDARD_FROM_DYNAMIC.name, p)
    q = np.vstack([sig.q[sig.inner()] for sig in signals])
    q = q[:: max(q.shape[0] // 200, 1)]
    n = q.shape[1]
    return np.median([np.diag(model("mass_matrix", x, s).reshape(n, n)) for x in q], axis=0)


def ranges(robot, model, c, fit) -> list[str]:
    out = []
    n = robot.dof
    f = c.friction
    tau = np.vstack([sig.tau[sig.inner()] for sig in fit])
    torque = np.sqrt(np.mean(tau ** 2, axis=0))
    inertia = _inertia_about_joints(model, c.p, fit)
    for j in range(n):
        ia = f["armature"][j]
        if np.isfinite(ia) and ia > ROTOR_RATIO * inertia[j]:
            out.append(f"joint {j + 1}: rotor inertia {ia:.3g} kg m^2 is {ia / inertia[j]:.0f} x the arm's own inertia "
                       f"about the joint ({inertia[j]:.3g} kg m^2): outside its physical range")
        b = f["offset"][j]
        if np.isfinite(b) and abs(b) > torque[j]:
            out.append(f"joint {j + 1}: offset {b:+.3g} Nm is larger than the measured torque's RMS ({torque[j]:.3g} Nm)")
        rc, rs = f.get("ripple_cos", np.full(n, np.nan))[j], f.get("ripple_sin", np.full(n, np.nan))[j]
        amplitude = float(np.hypot(np.nan_to_num(rc), np.nan_to_num(rs)))
        if amplitude > torque[j]:
            out.append(f"joint {j + 1}: position ripple of {amplitude:.3g} Nm is larger than the measured torque's RMS "
                       f"({torque[j]:.3g} Nm)")
        if c.lags is not None and np.any(np.nan_to_num(f["coulomb"]) > 0) and c.lags[j] >= LAG_GRID[-1] > 0:
            out.append(f"joint {j + 1}: the Coulomb lag {1e3 * c.lags[j]:.3g} ms is the last of its search grid: a bound, "
                       "not a finding")
        if c.smoothing[j] >= SMOOTHING_GRID[-1] and np.nan_to_num(f["coulomb"][j]) > 0:
            out.append(f"joint {j + 1}: the Coulomb smoothing {c.smoothing[j]:.3g} rad/s is the last of its search grid: "
                       "a bound, not a finding")
    return out


def held_out(model, c, fit, select, prior) -> tuple[list[str], dict | None]:
    """(warnings, {"identified": rms, "simple": rms} per joint on select), or None without select."""
    if not select or prior is None:
        return [], None
    s = model(STANDARD_FROM_DYNAMIC.name, prior)

    def residual(sig):
        return sig.tau - model.batch(RNEA.name, sig.q, sig.qd, sig.qdd, s)

    simple = baseline.fit([_Segment(sig, residual(sig), sig.inner()) for sig in fit])
    rows_id, rows_simple = [], []
    for sig in select:
        keep = sig.inner()
        rows_id.append((sig.tau - c.predict(model, sig))[keep])
        rows_simple.append((residual(sig) - baseline.predict(simple, _Segment(sig, None, keep)))[keep])
    rms_id = np.sqrt(np.mean(np.vstack(rows_id) ** 2, axis=0))
    rms_simple = np.sqrt(np.mean(np.vstack(rows_simple) ** 2, axis=0))
    worse = [j for j in range(rms_id.size) if rms_simple[j] < TIE * rms_id[j]]
    out = []
    if worse:
        out.append("the simple model (the prior + offset, Coulomb, viscous per joint) predicts the selection data "
                   "better than the identified model on joint(s) " + ", ".join(
                       f"{j + 1} ({rms_simple[j]:.3g} vs {rms_id[j]:.3g} Nm)" for j in worse)
                   + ": use the simple model there")
    return out, {"identified": rms_id.tolist(), "simple": rms_simple.tolist(), "simple_better": [j + 1 for j in worse]}


def check(robot, model, c, fit, select, prior) -> tuple[list[str], dict | None]:
    lines = ranges(robot, model, c, fit)
    more, table = held_out(model, c, fit, select, prior)
    return lines + more, table


def table_lines(table: dict | None) -> list[str]:
    if table is None:
        return ["No --select recordings: the identified model was not compared with the simple model on held-out "
                "data."]
    n = len(table["identified"])
    return ["RMS on the --select recordings [Nm] (neither model fitted them):", "",
            "| | " + " | ".join(f"J{j + 1}" for j in range(n)) + " |", "|---|" + "---:|" * n,
            "| identified | " + " | ".join(f"{x:.3g}" for x in table["identified"]) + " |",
            "| simple model | " + " | ".join(f"{x:.3g}" for x in table["simple"]) + " |"]
