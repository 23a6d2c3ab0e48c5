"""Identification sanity: every identified value inside its physical range, every search
that ended at its grid's edge named, and the result's prediction beside the simple model's.

    lines, table, result = check(robot, model, result, fit, select, prior)

Ranges (warnings, the values are kept and written):
  - rotor inertia: its torque Ia qdd_j (RMS over the fit data) at most the measured torque's RMS
    on its joint, and Ia at most ROTOR_RATIO times the arm's own inertia about the joint (the
    median of M_jj over the fit data). A reflected rotor inertia may well exceed the link's own
    inertia ten times on a wrist joint (gear ratio squared times the rotor's), so the ratio
    alone flagged a true 0.005 kg m^2 on the LWR's joint 7; 24 x that value once came out on a
    joint whose data could not separate it from an offset and a lag: its torque is then larger
    than the joint's whole torque;
  - an offset or a ripple amplitude: at most the RMS of the measured torque on its joint (a
    constant larger than the torque it sits in is a term making up for another);
  - the Coulomb lag and smoothing: a choice at the last value of its grid is a bound, not a
    finding (options.LAG_GRID, SMOOTHING_GRID). The lag's grid is not widened: on the real
    LWR4+ (fit m1, select m3) lags at its 40 ms end on joints 2-6 went to 80-160 ms when it was,
    and joint 5 then predicted m3 worse (0.299 against 0.262 Nm): a longer lag fits the fit data
    better without being a finding.
The simple model (terms/simple_model.py: the prior's residual fitted per joint by b + Fc
tanh(qd / 0.02) + Fv qd on the fit data) and the identified model are both judged on the
--select recordings, which neither fitted; a joint where the simple model predicts better is
named, with the advice to use the simple model: the result then predicts that joint by the prior's rigid body and the
simple model's three values (Consistent.simple, written as `simple_model:` in the YAML), as the
diagnosis does (diagnosis/joints.py). Without --select nothing held out exists, and the table
says so.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..catalogue import RNEA, STANDARD_FROM_DYNAMIC
from ..terms import simple_model as baseline
from .identify_options import LAG_GRID, SMOOTHING_GRID

ROTOR_RATIO = 100.0
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
    qdd = np.sqrt(np.mean(np.vstack([sig.qdd[sig.inner()] for sig in fit]) ** 2, axis=0))
    for j in range(n):
        ia = f["armature"][j]
        if np.isfinite(ia) and ia > ROTOR_RATIO * inertia[j]:
            out.append(f"joint {j + 1}: rotor inertia {ia:.3g} kg m^2 is {ia / inertia[j]:.0f} x the arm's own inertia "
                       f"about the joint ({inertia[j]:.3g} kg m^2): outside its physical range")
        elif np.isfinite(ia) and ia * qdd[j] > torque[j]:
            out.append(f"joint {j + 1}: rotor inertia {ia:.3g} kg m^2 makes {ia * qdd[j]:.3g} Nm (RMS), more than the "
                       f"measured torque's RMS ({torque[j]:.3g} Nm): outside its physical range")
        b = f["offset"][j]
        if np.isfinite(b) and abs(b) > torque[j]:
            out.append(f"joint {j + 1}: offset {b:+.3g} Nm is larger than the measured torque's RMS ({torque[j]:.3g} Nm)")
        rc, rs = f.get("ripple_cos", np.full(n, np.nan))[j], f.get("ripple_sin", np.full(n, np.nan))[j]
        amplitude = float(np.hypot(np.nan_to_num(rc), np.nan_to_num(rs)))
        if amplitude > torque[j]:
            out.append(f"joint {j + 1}: position ripple of {amplitude:.3g} Nm is larger than the measured torque's RMS "
                       f"({torque[j]:.3g} Nm)")
        if c.lags is not None and np.nan_to_num(f["coulomb"][j]) > 0 and c.lags[j] >= LAG_GRID[-1] > 0:
            out.append(f"joint {j + 1}: the Coulomb lag {1e3 * c.lags[j]:.3g} ms is the last of its search grid: a bound, "
                       "not a finding")
        if c.smoothing[j] >= SMOOTHING_GRID[-1] and np.nan_to_num(f["coulomb"][j]) > 0:
            out.append(f"joint {j + 1}: the Coulomb smoothing {c.smoothing[j]:.3g} rad/s is the last of its search grid: "
                       "a bound, not a finding")
    return out


def held_out(model, c, fit, select, prior):
    """(warnings, {"identified": rms, "simple": rms, "simple_better": joints} on select, or None
    without select, the result with the simple model where it predicts select better)."""
    if not select or prior is None:
        return [], None, c
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
                   + ": the simple model predicts there (simple_model: in the YAML; the URDF and MJCF carry the "
                     "identified links and friction)")
        c = replace(c, simple={"joints": worse, "values": simple.values, "prior": np.asarray(prior, dtype=float),
                               "standard": s})
    table = {"identified": rms_id.tolist(), "simple": rms_simple.tolist(), "simple_better": [j + 1 for j in worse]}
    return out, table, c


def check(robot, model, c, fit, select, prior):
    """(warnings, the held-out table or None, the result with the simple model where it won)."""
    lines = ranges(robot, model, c, fit)
    more, table, c = held_out(model, c, fit, select, prior)
    return lines + more, table, c


def table_lines(table: dict | None) -> list[str]:
    if table is None:
        return ["No --select recordings: the identified model was not compared with the simple model on held-out "
                "data."]
    n = len(table["identified"])
    return ["RMS on the --select recordings [Nm] (neither model fitted them):", "",
            "| | " + " | ".join(f"J{j + 1}" for j in range(n)) + " |", "|---|" + "---:|" * n,
            "| identified | " + " | ".join(f"{x:.3g}" for x in table["identified"]) + " |",
            "| simple model | " + " | ".join(f"{x:.3g}" for x in table["simple"]) + " |",
            "", "Predicted by the simple model (it did better there): "
            + (", ".join(f"J{j}" for j in table["simple_better"]) or "no joint") + "."]
