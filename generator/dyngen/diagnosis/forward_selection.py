"""Forward selection of effects by what they do on selection data (never on the fit's samples), and
prune(), backward elimination once their settings are refined (settle.py). A step takes the
candidate with the largest selection gain per sqrt of its values that is significant and plausible;
near ties go to the fewest values and plainer effects. Rules and reasons: docs/measured-data.md."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import linalg, stats

MIN_GAIN = 0.05
ALPHA = 1e-3
NEAR_BEST = 0.9


@dataclass
class Fit:
    x: np.ndarray  # values at the chosen slots
    slots: np.ndarray
    covariance: np.ndarray | None  # white-residual covariance (scaled later for correlation), or only
    # the block of `block` (see solve)
    block: slice | None = None


@dataclass
class Selection:
    chosen: list  # Candidate, in the order selected
    steps: list = field(default_factory=list)  # per step: {"candidate", "gain", "score"}
    first_gains: dict = field(default_factory=dict)  # candidate key -> gain when tried alone
    # (an extension, Term.extends: when first tried, beside its base effect)


def solve(design, chosen, block: slice | None = None, covariance: bool = True) -> Fit:
    """Weighted least squares of the chosen candidates on the fit samples (moments only).

    The covariance is the sandwich H^-1 (sum_j w_j^4 s_j^2 G_j) H^-1, s_j^2 joint j's own residual
    variance (the weights come from the nominal residual, not the noise). With `block` only that
    block of it; with covariance False none."""
    slots = np.concatenate([c.slots for c in chosen]) if chosen else np.zeros(0, dtype=int)
    apply, d = _factored(design.H[np.ix_(slots, slots)])
    x = apply(design.g[slots] / d) / d
    if not covariance:
        return Fit(x, slots, None, block)
    fit = design.fit
    w2 = design.weights ** 2
    G = fit.G[:, slots][:, :, slots]
    sse = np.maximum(fit.c - 2 * fit.b[:, slots] @ x + np.einsum("k,jkl,l->j", x, G, x), 0.0)
    s2 = sse / max(fit.count - len(slots), 1)  # per joint
    middle = np.einsum("j,jkl->kl", w2 ** 2 * s2, G)
    unit = np.eye(len(slots))[:, block if block is not None else slice(None)]
    columns = apply(unit / d[:, None]) / d[:, None]  # the needed columns of H^-1
    return Fit(x, slots, columns.T @ middle @ columns, block)


def _factored(H: np.ndarray):
    """(b -> Hs^-1 b, d) for H scaled to a unit diagonal Hs (units differ by orders): H^-1 b = Hs^-1 (b / d) / d;
    by Cholesky, or a pseudo-inverse when columns are dependent (they then share no value)."""
    d = np.sqrt(np.maximum(np.diag(H), 1e-300))
    Hs = H / np.outer(d, d)
    if Hs.size == 0:
        return (lambda b: np.zeros_like(b)), d
    try:
        factor = linalg.cho_factor(Hs, check_finite=False)
        if np.min(np.abs(np.diag(factor[0]))) > 1e-5:  # condition below about 1e10
            return (lambda b: linalg.cho_solve(factor, b, check_finite=False)), d
    except linalg.LinAlgError:
        pass
    vals, vecs = np.linalg.eigh(Hs)
    keep = vals > 1e-10 * max(vals.max(), 1e-300)
    inverse = (vecs[:, keep] / vals[keep]) @ vecs[:, keep].T
    return (lambda b: inverse @ b), d


def p_value(fit: Fit, candidate, chosen, correlation: float = 1.0) -> float:
    """Chi-square test of the candidate's values against zero, the covariance scaled by the correlation time."""
    offset = sum(c.size for c in chosen[:chosen.index(candidate)])
    k = slice(offset, offset + candidate.size)
    assert fit.block in (None, k), "covariance computed for another block"
    x, C = fit.x[k], (fit.covariance[k, k] if fit.block is None else fit.covariance) * correlation
    vals, vecs = np.linalg.eigh(C)
    keep = vals > 1e-12 * max(vals.max(initial=0.0), 1e-300)
    if not keep.any():
        return 1.0
    chi2 = float(np.sum((vecs[:, keep].T @ x) ** 2 / vals[keep]))
    return float(stats.chi2.sf(chi2, int(keep.sum())))


def selection_mse(design, chosen) -> np.ndarray:
    """Per joint mean square of the residual the chosen candidates leave on selection data: on the
    selection recordings, or with selection on blocks (design.groups) over every cut, each block
    group judging the fit on the others (one cut judges one phase of a periodic motion only)."""
    if not design.groups:
        if not chosen:
            return design.select.c / max(design.select.count, 1)
        fit = solve(design, chosen, covariance=False)
        return design.select.mse(fit.slots, fit.x)
    if not chosen:
        return sum(m.c for m in design.groups) / max(sum(m.count for m in design.groups), 1)
    slots = np.concatenate([c.slots for c in chosen])
    w2 = design.weights ** 2
    G_all = sum(m.G[:, slots][:, :, slots] for m in design.groups)
    b_all = sum(m.b[:, slots] for m in design.groups)
    sse = np.zeros(design.weights.size)
    for m in design.groups:
        G, b = m.G[:, slots][:, :, slots], m.b[:, slots]
        H = np.einsum("j,jkl->kl", w2, G_all - G)
        g = w2 @ (b_all - b)
        apply, d = _factored(H)
        x = apply(g / d) / d
        sse += np.maximum(m.c - 2 * b @ x + np.einsum("k,jkl,l->j", x, G, x), 0.0)
    return sse / max(sum(m.count for m in design.groups), 1)


def selection_gain(candidate, before: np.ndarray, after: np.ndarray) -> float:
    """Relative decrease of the selection mean square: a per-joint effect's on its own joint, less any
    increase on other joints (through the refit arm-wide values); an arm-wide effect's summed."""
    relative = relative_change(before, after)
    if candidate.joint is None:
        return float(relative.sum())
    return float(relative[candidate.joint] + np.minimum(np.delete(relative, candidate.joint), 0.0).sum())


def forward(design, min_gain: float = MIN_GAIN, alpha: float = ALPHA, max_steps: int = 30) -> Selection:
    """Forward steps; their significance test assumes uncorrelated residuals (prune() scales it)."""
    selection = Selection([])
    current = selection_mse(design, [])
    while len(selection.chosen) < max_steps:
        families = {c.family for c in selection.chosen}
        trials = []
        for cand in design.candidates:
            if cand.family in families or not _based(cand, selection.chosen):
                continue
            chosen = selection.chosen + [cand]
            fit = solve(design, chosen, covariance=False)
            mse = selection_mse(design, chosen)
            gain = selection_gain(cand, current, mse)
            if not selection.chosen or (cand.effect.extends and cand.key not in selection.first_gains):
                selection.first_gains[cand.key] = gain
            if gain >= min_gain * np.sqrt(cand.size) and cand.effect.plausible(fit.x[-cand.size:]) \
                    and _shown(cand, current, mse, min_gain):
                size = len(fit.x)
                fit = solve(design, chosen, block=slice(size - cand.size, size))
                trials.append((gain, cand, mse, fit, chosen))
        qualified = [t for t in trials if p_value(t[3], t[1], t[4]) < alpha]
        if not qualified:
            break
        earned = lambda t: t[0] / np.sqrt(t[1].size)  # noqa: E731  gain over its price of entry
        best = max(earned(t) for t in qualified)
        near = [t for t in qualified if earned(t) >= NEAR_BEST * best]
        if any(not t[1].effect.secondary for t in near):  # a tie goes to the plainer explanation
            near = [t for t in near if not t[1].effect.secondary]
        gain, cand, mse, _, _ = min(near, key=lambda t: (t[1].size, -t[0]))
        selection.chosen.append(cand)
        selection.steps.append({"candidate": cand.key, "gain": gain, "selection_rms": np.sqrt(mse).tolist()})
        current = mse
    return selection


def _shown(candidate, before, after, min_gain) -> bool:
    """An arm-wide effect must gain min_gain on two joints (on one, that joint's own effects explain it)."""
    relative = relative_change(before, after)
    return candidate.joint is not None or int(np.sum(relative >= min_gain)) >= min(2, len(relative))


def relative_change(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """Per joint relative change of the selection mean square (a decrease positive), over the larger of
    before and after: undoing a step scores exactly minus the step, so pruning judges as selection did."""
    return (before - after) / np.maximum(np.maximum(before, after), 1e-300)


def bases(candidate, chosen) -> list:
    """The chosen effects on the candidate's joint that it extends (Term.extends)."""
    name = candidate.effect.extends
    return [c for c in chosen if name and c.effect.name == name and c.joint == candidate.joint]


def _based(candidate, chosen) -> bool:
    """Whether the effect a candidate extends (if any) is chosen on its joint."""
    return not candidate.effect.extends or bool(bases(candidate, chosen))


def without(chosen, cand) -> tuple[list, list]:
    """(chosen less cand and the effects that extend it on its joint, the candidates removed: cand first)."""
    kept = [c for c in chosen if c is not cand]
    gone = [c for c in kept if not _based(c, kept)]
    return [c for c in kept if c not in gone], [cand] + gone


def prune(design, chosen: list, correlation, alpha: float = ALPHA, min_gain: float = 0.0) -> tuple[list, float, list]:
    """Backward elimination: drop the effect furthest below `min_gain` per sqrt of its values (the
    price of entry in forward()), then, deviations scaled by the correlation time of what the chosen
    leave (correlation(chosen, fit) -> samples), the least significant while its p-value exceeds alpha.
    Returns (kept, correlation time, dropped keys)."""
    chosen, dropped = list(chosen), []

    def drop(index):
        nonlocal chosen
        chosen, gone = without(chosen, chosen[index])
        dropped.extend(c.key for c in gone)

    while True:
        fit = solve(design, chosen)
        tau = correlation(chosen, fit)
        if not chosen:
            return chosen, tau, dropped
        with_all = selection_mse(design, chosen)
        # An effect that no longer pays on selection data once the others are in goes first.
        gains = [selection_gain(c, selection_mse(design, [o for o in chosen if o is not c]), with_all) for c in chosen]
        margin = [g - min_gain * np.sqrt(c.size) for g, c in zip(gains, chosen)]  # over the price of entry
        worst = int(np.argmin(margin))
        if margin[worst] < 0 or gains[worst] <= 0:
            drop(worst)
            continue
        pvalues = [p_value(fit, c, chosen, tau) for c in chosen]
        worst = int(np.argmax(pvalues))
        if pvalues[worst] <= alpha:
            return chosen, tau, dropped
        drop(worst)
