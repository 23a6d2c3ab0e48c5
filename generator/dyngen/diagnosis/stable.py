"""A finding is stable across the fit data, or it is not claimed: each chosen effect's values,
fitted again (all effects together) on each of STRETCHES contiguous stretches of every fit
recording, against the values from every fit sample. It is "unstable across blocks" where a
stretch's values differ beyond their uncertainty (chi-square with the stretch's covariance,
scaled for the residual's correlation, above its 1 - ALPHA quantile) and move the effect's
torque over the stretch by more than MOVES of it (weighted norm over the stretch's samples: a
sign change moves it by more than 1) beyond MARGIN times the stretch's own uncertainty of that
share, or leave its physical range. Values a stretch does not determine count only through the
torque they make there, a stretch whose uncertainty of the effect's torque over it (the
trace of its normal matrix times the values' covariance) exceeds the torque the whole fit's
values make there does not vote at all: for one value, a standard deviation above the value.
Values outside the physical range make it unstable only on more than STRAY of the stretches that vote.
The effect stays in the model; it is reported as record.Unstable instead of a finding
(docs/measured-data.md, "A finding is stable across the fit data").
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.stats import chi2

from .findings import identifiable
from .forward_selection import solve
from .refine import restricted

STRETCHES = 3
ALPHA = 1e-3
MOVES = 0.5
# ... by more than MARGIN of the stretch's own uncertainty of that share: a decision at the
# threshold is one that rounding or noise can flip (UR5 trial, joint 4's true rotor inertia: a
# stretch 54 % off against the 50 %, that share known to 15 %)
MARGIN = 2.0
# a value is determined on a stretch when less than this share of it lies in the directions the
# stretch does not determine: two values that are one column there (Coulomb and an offset on a
# joint that moves one way only) have 0.5 each, and findings.identifiable's own < 0.5 then
# decided by rounding which of them a stretch determined (the 5-min 1 kHz LWR file, joint 5:
# with G(q) summed in another order the Coulomb friction, else the offset, voted unstable)
LOADING = 0.1
# Values outside the physical range make an effect unstable only on more than this share of the
# stretches that vote: a physical value that moved is the effect changing (a gain in the first
# third only), while one or two stretches of nine with impossible values are where the arm stuck
# and no friction law fits four seconds (the Panda trial's wrist under MuJoCo's sticky friction:
# joint 5's true rotor inertia 0.05 from every fit sample, -0.31 on stretch 8 alone, and its
# viscous friction negative on stretches 6 and 8 alone; joint 6's on one stretch of nine)
STRAY = 0.25


def _stretched(segments):
    """The segments with Segment.groups as every fit recording's STRETCHES contiguous stretches of
    fit samples (equal counts), one group per stretch over all segments."""
    fitting = [i for i, seg in enumerate(segments) if seg.fit.any()]
    total, out = STRETCHES * len(fitting), []
    for i, seg in enumerate(segments):
        groups = [np.zeros(seg.fit.size, dtype=bool) for _ in range(total)]
        if i in fitting:
            first = STRETCHES * fitting.index(i)
            for b, idx in enumerate(np.array_split(np.flatnonzero(seg.fit), STRETCHES)):
                groups[first + b][idx] = True
        out.append(replace(seg, groups=groups))
    return out, total


def unstable(context, segments, design, chosen, x, tau_corr, faint=()) -> dict:
    """chosen index -> (values per stretch, each a list or None where undetermined, reason) for
    the effects that are unstable across the stretches. `faint`: indices of effects below the
    significance floor (findings_check.below_floor), left out of the stretches' fits: no finding,
    they must not take a finding's share on a stretch (the Panda trial, joint 5: a 0.004 Nm ripple,
    on a 4-s stretch of one harmonic a column of q much like the rotor inertia's qdd, drove the
    true rotor inertia to -0.23 there)."""
    if faint:
        keep = [i for i in range(len(chosen)) if i not in faint]
        kept = [chosen[i] for i in keep]
        own, renumbered = restricted(context, segments, design, kept)
        return {keep[i]: v for i, v in unstable(context, segments, design, kept, solve(own, renumbered).x,
                                                  tau_corr).items()}
    if not chosen:
        return {}
    cut, total = _stretched(segments)
    whole, renumbered = restricted(context, cut, replace(design, groups=[None] * total), chosen)
    overall = identifiable(whole, renumbered)
    fits = []
    for m in whole.groups:
        part = type(whole)(renumbered, m, m, m, whole.weights)
        fits.append((solve(part, renumbered), identifiable(part, renumbered, LOADING), part.H) if m.count
                    else (None,) * 3)
    out = {}
    for i, c in enumerate(renumbered):
        k = c.slots
        values, why, voting, outside = [], [], 0, 0
        for b, (f, ok, H) in enumerate(fits):
            values.append(None if f is None else [float(v) if u else None for v, u in zip(f.x[k], overall[k] & ok[k])])
            if f is None or not ok[k].any():
                continue
            # compared as torques: directions the stretch does not determine carry its large
            # variance (chi-square) and little of its torque (the stretch's own normal matrix)
            diff, H_b, cov = f.x[k] - x[k], H[np.ix_(k, k)], f.covariance[np.ix_(k, k)] * tau_corr
            # the stretch's uncertainty of the effect's torque over it, relative to the whole fit's
            spread = np.sqrt(np.trace(H_b @ cov) / max(x[k] @ H_b @ x[k], 1e-300))
            if spread > 1:
                continue  # the stretch does not determine the effect's torque over it: no vote
            voting += 1
            ev, V = np.linalg.eigh(cov)
            keep = ev > 1e-12 * max(ev.max(), 1e-300)
            if np.sum((V[:, keep].T @ diff) ** 2 / ev[keep]) <= chi2.ppf(1 - ALPHA, keep.sum()):
                continue
            moved = np.sqrt(diff @ H_b @ diff / max(x[k] @ H_b @ x[k], 1e-300))
            inside = c.effect.plausible(np.where(overall[k] & ok[k], f.x[k], x[k]))
            outside += not inside
            if moved - MARGIN * spread > MOVES or not inside:
                why.append(f"stretch {b + 1}: " + ("outside its physical range" if not inside else
                                                   f"its torque {moved:.0%} +- {spread:.0%} off the whole fit's"))
        if len(why) > outside or outside > STRAY * voting:
            out[i] = (values, f"values on {STRETCHES} stretches of each fit recording fitted on their own differ from "
                              f"the whole fit's beyond their uncertainty ({'; '.join(why)})")
    return out

