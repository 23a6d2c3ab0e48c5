"""Identification sanity: every identified value inside its physical range (warnings; the
values are kept), every search that ended at its grid's edge named (the Coulomb lag and smoothing, the
prior's weight: a bound, not a finding; the lag grid is not widened, docs/measured-data.md says why), and the result's prediction beside
the simple model's on the --select recordings, which neither fitted. Where the simple model
predicts a joint better, the result predicts it as the diagnosis does (diagnosis/joints.py):
the prior's rigid body and the simple model's three values (Consistent.simple).

    lines, table, result = check(robot, model, result, fit, select, prior)
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..catalogue import RNEA, STANDARD_FROM_DYNAMIC
from ..terms import simple_model as baseline
from .identify_options import LAG_GRID, SMOOTHING_GRID

ROTOR_RATIO = 100.0  # x the arm's own inertia about the joint (a UR wrist's true one is 200-500 x) ...
ROTOR_SHARE = 0.5  # ... and its torque over this share of the measured torque's RMS: both, or it is physical
TIE = 1.0  # the simple model is preferred where its held-out RMS is below TIE x the identified model's


@dataclass
class _Segment:  # what baseline.fit reads
    signals: object
    residual: np.ndarray
    fit: np.ndarray


def inertia_about_joints(model, s, signals) -> np.ndarray:
    """Per joint the median of M_jj (standard parameters s) over about 200 of the signals' positions."""
    q = np.vstack([sig.q[sig.inner()] for sig in signals])
    n = q.shape[1]
    return np.median([np.diag(model("mass_matrix", x, s).reshape(n, n)) for x in q[:: max(q.shape[0] // 200, 1)]], axis=0)


def rotor_inertia_range(j: int, ia: float, own: float, qdd: float, torque: float) -> str | None:
    """Why joint j's (0-based) rotor inertia ia [kg m^2] is outside its physical range, or None.
    own: the arm's inertia about the joint; qdd, torque: the joint's acceleration and measured
    torque (RMS). A reflected rotor inertia (gear ratio squared times the rotor's) is often
    hundreds of times a light wrist link's own inertia, so size alone is no verdict: it is out of
    range where its torque is more than the measured torque, or where it is both over ROTOR_RATIO x
    the link's inertia and carries most of the torque (the issue's 0.121 kg m^2 on the LWR's joint 7)."""
    if not np.isfinite(ia):
        return None
    if ia * qdd > torque:
        return (f"joint {j + 1}: rotor inertia {ia:.3g} kg m^2 makes {ia * qdd:.3g} Nm (RMS), more than the measured "
                f"torque's RMS ({torque:.3g} Nm): outside its physical range")
    if ia > ROTOR_RATIO * own and ia * qdd > ROTOR_SHARE * torque:
        return (f"joint {j + 1}: rotor inertia {ia:.3g} kg m^2 is {ia / own:.0f} x the arm's own inertia about the joint "
                f"({own:.3g} kg m^2) and makes {ia * qdd / torque:.0%} of its measured torque (RMS): outside its "
                "physical range")
    return None


def ranges(robot, model, c, fit) -> list[str]:
    out = []
    n = robot.dof
    f = c.friction
    tau = np.vstack([sig.tau[sig.inner()] for sig in fit])
    torque = np.sqrt(np.mean(tau ** 2, axis=0))
    inertia = inertia_about_joints(model, model(STANDARD_FROM_DYNAMIC.name, c.p), fit)
    qdd = np.sqrt(np.mean(np.vstack([sig.qdd[sig.inner()] for sig in fit]) ** 2, axis=0))
    for j in range(n):
        rotor = rotor_inertia_range(j, f["armature"][j], inertia[j], qdd[j], torque[j])
        if rotor:
            out.append(rotor)
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
    tried = [x for x, _ in c.selection]
    if len(tried) > 1 and c.regularisation >= max(tried):  # held-out data asked for the most prior tried
        out.append(f"the prior's weight {c.regularisation:g}, chosen on held-out data, is the last of its search grid: "
                   "a bound, the data determine the links poorly")
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
