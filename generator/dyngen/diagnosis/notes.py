"""What a reader must know beside the figures: the warnings of a diagnosis."""

from __future__ import annotations

import numpy as np

from . import roles
from ..terms import effect_class

EXTRAPOLATION = 1.2  # warn when test speeds exceed the fit data's by this factor
DIFFERENTIATION_SHARE = 0.5  # warn when differentiation noise is this share of a joint's residual variance


def notes(d, model, s, fit_signals, select_signals, test_signals, used) -> list[str]:
    out = [w for sig in [*fit_signals, *select_signals, *test_signals] for w in sig.warnings]
    if d.judged_on == "selection":
        out.append("no test recording (--test): the residual 'after' is measured on the selection data, which chose "
                   "the effects; it is not a held-out figure")
    # Laws fitted on one range of motion and judged beyond it (friction at higher speeds).
    if test_signals:
        fast_fit, fast_test = (np.max(np.vstack([np.abs(sig.qd[sig.inner()]) for sig in group]), axis=0)
                               for group in (fit_signals, test_signals))
        beyond = [j for j in range(d.joints) if fast_test[j] > EXTRAPOLATION * fast_fit[j]]
        if beyond:
            out.append("the test data move joint(s) " + ", ".join(
                f"{j + 1} ({fast_test[j]:.2g} vs {fast_fit[j]:.2g} rad/s)" for j in beyond)
                + " faster than any fit data: velocity-dependent laws are extrapolated there")
    for fit, test, diff in roles.repeated(fit_signals, test_signals):
        out.append(f"{test} repeats the trajectory of {fit} (RMS position difference {diff:.3g} rad): the test shows "
                   "that the effects repeat, not that they generalise to other motions")
    # Differentiation noise carried into the model torque: M(q) times the acceleration noise.
    for seg in used:
        sig = seg.signals
        if sig.qdd_noise is None:
            continue
        M = model("mass_matrix", np.median(sig.q, axis=0), s).reshape(d.joints, d.joints)
        predicted = np.sqrt((M ** 2) @ (np.asarray(sig.qdd_noise) ** 2))
        bad = [j for j in range(d.joints) if predicted[j] ** 2 > DIFFERENTIATION_SHARE * d.rms_after[j] ** 2]
        if bad:
            out.append(f"{sig.name}: noise of the differentiated positions makes up most of the residual on joint(s) "
                       f"{', '.join(str(j + 1) for j in bad)} (about "
                       f"{', '.join(f'{predicted[j]:.3g}' for j in bad)} Nm of {', '.join(f'{d.rms_after[j]:.3g}' for j in bad)}"
                       " Nm): recorded velocities, or a lower --cutoff, would lower it")
    for e in d.selected:
        out += effect_class(e.effect).warnings(e)
        if e.suspect:
            out.append(f"{e.effect} may be a symptom rather than a cause: {e.suspect}")
    for r in d.refused:
        shown = ", ".join(f"{v:.3g}" for v in r.values[:4])
        because = "; ".join(x for x in (shown, r.reason) if x)
        what = "" if r.reason else ", its fitted values are not physically possible"
        out.append(f"{r.candidate}: refused{what} ({because})")
    if d.consistent:
        c = d.consistent
        out.append("link parameters off: on joint(s) " + ", ".join(map(str, c.joints)) + " physically consistent "
                   "link parameters re-identified from the fit data (every link's pseudo-inertia positive definite; "
                   "with per-joint Coulomb, viscous, offset, rotor inertia, position ripple and a tilted base; "
                   f"regularised toward the given parameters with weight {c.regularisation:g}, chosen on selection "
                   "data from " + ", ".join(f"{s['regularisation']:g}" for s in c.selection) + ") did better than "
                   "every effect and the simple model on selection data, and are used there; they are in "
                   "consistent/identified.yaml (URDF and MJCF beside it)")
    if d.simple_wins:
        out.append("on joint(s) " + ", ".join(map(str, d.simple_wins)) + " the simple model (offset + Coulomb + viscous) "
                   "did better than the selected effects on selection data and is kept there")
    return out
