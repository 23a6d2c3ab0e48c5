"""Stage 4, choose per joint: the effects, the simple model, both, or re-identified link
parameters, on selection data (joints.py decides; here the cuts of the fit recordings into
fit and selection blocks, and the consistent re-identification, reidentify.py)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..terms import simple_model
from . import joints, reidentify, roles
from .fit import corrected, ranged
from .refine import restricted
from .forward_selection import solve


def on_folds(context, segments, design, chosen, options) -> list[str]:
    """Per joint model (joints.py) from selection errors summed over the roles.FOLDS cuts, refitted per cut."""
    totals = None
    for phase in range(roles.FOLDS):
        cut = [replace(seg, **dict(zip(("fit", "select"), roles.blocks(seg.signals, options.block_seconds, phase))))
               if seg.fit.any() or seg.select.any() else seg for seg in segments]
        # Position laws are known only over the positions this cut's fit blocks cover, as the
        # final model's are over all the fit data (else a ripple would be judged on guesses).
        fold = ranged(context, cut, chosen)
        x = solve(*restricted(fold, cut, design, chosen), covariance=False).x if chosen else np.zeros(0)
        cut = corrected(fold, chosen, x, cut)
        sse = joints.errors(fold, cut, chosen, x, simple_model.fit(cut))
        totals = sse if totals is None else [{k: a[k] + b[k] for k in a} for a, b in zip(totals, sse)]
    return joints.choose(totals, chosen, joints.FOLDS_PER_VALUE)


def reidentified(robot, model, p, context, segments, chosen, x, simple, modes, min_gain, flagged):
    """(Consistent result, its corrections per segment, modes, tried) where the consistent link
    parameters win a joint on selection data, else (None, None, modes, tried) (reidentify.py);
    only on the joints `flagged` by reidentify.gate. tried: the result wherever it ran (what its
    links explain is not told apart from them, across.explained_by_links, won or not)."""
    if not flagged:
        return None, None, modes, None
    result = reidentify.identify(robot, model, p, reidentify.pieces(segments, "fit"),
                                 reidentify.pieces(segments, "select"))
    consistent = reidentify.corrections(result, model, segments)
    new = joints.decide(context, segments, chosen, x, simple, min_gain, consistent, reidentify.JOINT_VALUES)
    # only on joints whose residual the link parameters were shown to explain (the gate)
    new = [m if m != joints.CONSISTENT or j in flagged else old for j, (m, old) in enumerate(zip(new, modes))]
    return (result, consistent, new, result) if joints.CONSISTENT in new else (None, None, modes, result)


def refit(robot, model, p, segments, reid, consistent):
    """The consistent model refitted on every fit sample, kept unless it fits worse (reidentify.REFIT_WORSE)."""
    refit = reidentify.identify(robot, model, p, reidentify.pieces(segments, "fit"), regularisation=reid.regularisation)
    if np.all(refit.residual_rms <= reidentify.REFIT_WORSE * reid.residual_rms):
        return refit, reidentify.corrections(refit, model, segments)
    return reid, consistent
