"""A finding is physical or it is flagged `suspect`: an offset, ripple or rotor inertia whose torque
exceeds LARGER times its joint's nominal residual, or a rotor inertia outside identify's range.
And a finding's torque is above the significance floor, or it is not a finding: FLOOR of the
torque sensor's own noise (one sample's sigma, from the raw torques as logged), per joint.

    selected, warnings = check(selected, selection_before, model, s, fit_signals)
    low = below_floor(context, segments, chosen, x, floor(fit_signals))
    sticking = static_not_shown(context, segments, chosen, x, tau_corr)   # index -> why a Stribeck term is flagged

A Stribeck term stands for static friction above the Coulomb level: where it acts, the friction
measured must exceed that level by more than its standard error, or the term is flagged (it stays
in the model). A joint that sticks at rest (MuJoCo's frictionloss, most real joints) holds any
torque up to its friction there, while a Coulomb law of the filtered velocity falls to zero: a
Stribeck term, filtered like the torque, fits that held torque (the UR5 trial, joint 2: Fs 8.7 Nm
beside Fc 3.9 Nm, where the friction measured stays 0.35 Nm below the Coulomb level).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..data.automatic import position_noise
from ..data.glitches import despiked
from ..identification.sanity import inertia_about_joints, rotor_inertia_range
from .fit import predict
from .moments import split_values

LARGER = 1.5  # a term whose torque exceeds this many times its joint's whole nominal residual (RMS)
# An effect whose torque (RMS over the fit samples, on every joint it acts on) is below this share
# of one torque sample's noise sigma is not a finding, however many samples make it significant:
# what is left at that size is the model's own mismatch as much as the effect (trials of
# bench/trial_other_arm.py, none of them simulated: a 0.0045 Nm ripple on the Panda's joint 5
# beside 0.03 Nm noise, offsets of 0.006-0.009 Nm on the UR5's joint 6 beside 0.08 Nm). The
# smallest true effect of those trials is 3.7 sigma (the Panda's Coulomb 0.3 Nm on joint 7 at 0.08).
FLOOR = 0.25


def floor(fit_signals) -> np.ndarray | None:
    """Per joint the significance floor [Nm]: FLOOR times the torque noise sigma of the raw
    torques as logged (robust third differences, automatic.position_noise; rows that repeat the
    one before and spikes left out), the median over the fit recordings; None where no raw torques are kept."""
    sigmas = []
    for sig in fit_signals:
        raw = getattr(sig.source, "tau", None)
        if raw is None or raw.shape[0] < 8:
            continue
        moved = np.r_[True, np.any(np.diff(sig.source.q, axis=0) != 0, axis=1)]
        sigmas.append(position_noise(despiked(raw[moved])[0]))  # a bus's single wrong samples are no noise
    return FLOOR * np.median(sigmas, axis=0) if sigmas else None


def below_floor(context, segments, chosen, x, floors) -> dict[int, float]:
    """chosen index -> its torque's RMS [Nm] (the largest over the joints it acts on, fit samples)
    for the chosen effects below the floor on every joint."""
    if floors is None or not chosen:
        return {}
    fitting = [seg for seg in segments if seg.fit.any()]
    out = {}
    for i, (c, v) in enumerate(zip(chosen, split_values(chosen, x))):
        if c.effect.scales:  # a gain scales every torque on its joint, the other effects' included
            torque = np.concatenate([v[0] * np.where(np.arange(seg.signals.tau.shape[1]) == c.joint,
                                                     seg.signals.tau[seg.fit], 0.0) for seg in fitting])
        else:
            torque = np.concatenate([predict(context, [c], v, seg)[seg.fit] for seg in fitting])
        rms = np.sqrt(np.mean(torque ** 2, axis=0))
        if np.all(rms < floors):
            out[i] = float(rms.max())
    return out


def static_not_shown(context, segments, chosen, x, tau_corr: float = 1.0) -> dict[int, str]:
    """chosen index -> why, for the Stribeck terms whose static friction the fit samples do not show:
    on the samples where the term makes over half its largest torque (its core), the friction
    measured (what the effects leave, plus this term's and its Coulomb term's torques, signed by
    the velocity) exceeds the Coulomb level by no more than twice its standard error (samples
    counted over the residual's correlation time tau_corr)."""
    values = split_values(chosen, x)
    out = {}
    for i, c in enumerate(chosen):
        base = [k for k, o in enumerate(chosen) if c.effect.extends and o.effect.name == c.effect.extends
                and o.joint == c.joint]
        if not base or c.joint is None:
            continue
        j, b = c.joint, base[0]
        excess = []
        for seg in segments:
            if not seg.fit.any():
                continue
            own, coulomb = (predict(context, [chosen[k]], values[k], seg)[:, j] for k in (i, b))
            sign = np.sign(seg.signals.qd[:, j])
            measured = seg.residual[:, j] - seg.correction[:, j] + own + coulomb
            excess.append((sign * own, sign * measured - values[b][0], seg.fit))
        peak = max((float(np.max(s[f], initial=0.0)) for s, _, f in excess), default=0.0)
        if peak <= 0:
            continue
        e = np.concatenate([m[f & (s > 0.5 * peak)] for s, m, f in excess])
        if e.size < 2:
            continue
        se = float(np.std(e)) * np.sqrt(max(tau_corr, 1.0) / e.size)
        if e.mean() <= 2 * se:
            out[i] = (f"on joint {j + 1}, the static friction it stands for (the Coulomb level {values[b][0]:.3g} Nm plus "
                      f"{values[i][0]:.3g} Nm) is not seen: where it acts, the friction measured exceeds the Coulomb "
                      f"level by {e.mean():.3g} +- {se:.2g} Nm; a joint that sticks at rest holds any torque up to its "
                      "friction, which the term fits as well")
    return out


def _links_column(model, fit_signals, j) -> str | None:
    """Why a rotor inertia on joint j (0-based) is a link parameter, or None: its torque (Ia qdd_j
    on joint j alone) lies in the span of the rigid body's base columns (a first joint turning
    about the fixed vertical: ZZ1's column), so no data tell it from the links' inertia, and
    links identified from the same kind of data already carry it (identify writes Ia: null)."""
    sig = fit_signals[0]
    k = np.arange(sig.t.size)[sig.inner()][:: max(sig.t.size // 400, 1)]
    Y = model.batch("regressor", sig.q[k], sig.qd[k], sig.qdd[k])
    a = np.zeros(Y.shape[:2])
    a[:, j] = sig.qdd[k, j]
    A = Y.reshape(-1, Y.shape[2])
    left = A @ np.linalg.lstsq(A, a.ravel(), rcond=None)[0] - a.ravel()
    if np.linalg.norm(left) > 1e-6 * np.linalg.norm(a):
        return None
    return (f"on joint {j + 1}, a rotor inertia is one column with the links' base coefficients (its torque lies in "
            "their span): not told apart from the link parameters, which carry it")


def _size(e) -> float | None:
    """The size [Nm] of a per-joint finding's torque, where it has one of its own."""
    if e.effect == "offset" and e.values.get("b") is not None:
        return abs(e.values["b"])
    if e.effect == "ripple":
        rms = e.derived.get("torque_rms_Nm")
        return None if rms is None else float(rms)
    return None


def check(selected, selection_before, model, s, fit_signals) -> tuple[list, list[str]]:
    """(the findings, those outside their range marked suspect; what could not be told apart)."""
    before = np.asarray(selection_before, dtype=float)
    out, large, checked = [], {}, []
    inertia = None
    for e in selected:
        checked.append(e)
        if len(e.joints) != 1 or e.effect not in ("offset", "ripple", "armature"):
            continue
        j = e.joints[0] - 1
        reason = None
        size = _size(e)
        if size is not None and size > LARGER * before[j]:
            reason = (f"on joint {j + 1}, its torque ({size:.3g} Nm) is larger than the joint's whole nominal residual "
                      f"({before[j]:.3g} Nm on the selection data): it makes up for another term")
        if e.effect == "armature" and e.values.get("Ia") is not None:
            if inertia is None:
                inertia = inertia_about_joints(model, s, fit_signals)
            ia = e.values["Ia"]
            qdd, torque = (np.sqrt(np.mean(np.concatenate([getattr(sig, x)[sig.inner(), j] for sig in fit_signals]) ** 2))
                           for x in ("qdd", "tau"))
            reason = rotor_inertia_range(j, ia, inertia[j], qdd, torque) or _links_column(model, fit_signals, j)
            if not reason and ia * qdd > LARGER * before[j]:
                reason = (f"on joint {j + 1}, its torque ({ia * qdd:.3g} Nm) is larger than the joint's whole nominal "
                          f"residual ({before[j]:.3g} Nm on the selection data): it makes up for another term")
        if reason:
            checked[-1] = replace(e, suspect=reason)
            large.setdefault(j, []).append(e.effect)
    for j, names in sorted(large.items()):
        if len(names) > 1:
            out.append(f"joint {j + 1}: {' and '.join(names)} make up for each other; the data cannot tell them apart")
    return checked, out
