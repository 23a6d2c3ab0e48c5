"""Stage 3, refine and settle: the selected effects with their nonlinear settings refined
(refine.py), those that no longer pay for their values pruned, implausible ones refused and
impossible ones simplified (a payload whose inertia is no body's)."""

from __future__ import annotations

from . import moments as dz
from .record import Refusal
from .refine import refine, restricted
from .forward_selection import bases, prune, selection_mse, solve, without


def settle(context, segments, design, chosen, correlation, options):
    # Settings first (velocity scales, exact time shift and tilt), then pruning: a Stribeck term
    # that only made up for a Coulomb velocity scale on its variant grid goes once the scale is fitted.
    design, chosen = refine(context, segments, design, chosen)
    before = chosen
    chosen, _, dropped = prune(design, chosen, correlation, options.alpha, options.min_gain)
    narrow = _narrow_stribeck(chosen)
    chosen = [c for c in chosen if c not in narrow]
    dropped += [f"{c.key} (no wider than the joint's Coulomb transition: it only reshapes it)" for c in narrow]
    if dropped:
        if _moved(context, chosen, before):
            design, chosen = restricted(context, segments, design, chosen)
        design, chosen = refine(context, segments, design, chosen)
    before = chosen
    chosen, final, refused = _plausible(design, chosen)
    if _moved(context, chosen, before):
        design, chosen = restricted(context, segments, design, chosen)
        final = solve(design, chosen)
    design, chosen, final = _consistent_payload(context, segments, design, chosen, final, refused)
    return design, chosen, final, dropped, refused


def _moved(context, chosen, before) -> bool:
    """Whether dropping some of `before` changed what the others' columns are computed with (world)."""
    return dz.world(context, chosen) != dz.world(context, before)


def _plausible(design, chosen):
    """The final fit, after refusing, worst first, effects whose values fitted together are impossible."""
    refused = []
    while True:
        final = solve(design, chosen)
        values = dict(zip(map(id, chosen), dz.split_values(chosen, final.x)))
        reasons = {}
        for c in chosen:
            if not c.effect.plausible(values[id(c)]):
                reasons[id(c)] = ""
            for base in bases(c, chosen):
                why = c.effect.refusal_beside(values[id(c)], values[id(base)])
                if why:
                    reasons[id(c)] = f"beside {base.key} at {', '.join(f'{v:.3g}' for v in values[id(base)])}: {why}"
        worst = next((c for c in chosen if id(c) in reasons), None)
        if worst is None:
            return chosen, final, refused
        refused.append(Refusal(worst.key, values[id(worst)].tolist(), reasons[id(worst)]))
        chosen, gone = without(chosen, worst)  # a Stribeck term whose Coulomb was refused goes with it
        refused += [Refusal(c.key, [], f"{worst.key} refused") for c in gone[1:]]


def _consistent_payload(context, segments, design, chosen, final, refused):
    """An effect possible only in part (Term.simplified: a payload whose inertia is no body's) replaced by
    the simpler form that does best on the selection data, and everything refitted."""
    for i, (c, values) in enumerate(zip(chosen, dz.split_values(chosen, final.x))):
        simpler = c.effect.simplified(values)
        if simpler is None:
            continue
        refusal, forms = simpler
        tried = [restricted(context, segments, design,
                            chosen[:i] + [dz.Candidate(effect, c.joint, 0, len(effect.parameters))] + chosen[i + 1:])
                 for effect in forms]  # (design, chosen) per simpler form
        w2 = design.weights ** 2
        design, chosen = min(tried, key=lambda form: float(w2 @ selection_mse(*form)))
        refused.append(Refusal(*refusal))  # what of the term is refused, its values
        return design, chosen, solve(design, chosen)
    return design, chosen, final


def _narrow_stribeck(chosen) -> list:
    """Per-joint effects that only reshape another on their joint (Term.reshapes)."""
    return [c for c in chosen if c.joint is not None
            and any(o.joint == c.joint and c.effect.reshapes(o.effect) for o in chosen)]
