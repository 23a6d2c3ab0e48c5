"""A finding is physical or it is flagged `suspect`: an offset, ripple or rotor inertia whose torque
exceeds LARGER times its joint's nominal residual, or a rotor inertia outside identify's range.

    selected, warnings = check(selected, selection_before, model, s, fit_signals)"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..identification.sanity import inertia_about_joints, rotor_inertia_range

LARGER = 1.5  # a term whose torque exceeds this many times its joint's whole nominal residual (RMS)


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
            reason = rotor_inertia_range(j, ia, inertia[j], qdd, torque)
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
