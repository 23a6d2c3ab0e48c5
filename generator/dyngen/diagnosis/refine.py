"""Nonlinear settings of selected effects, refined on the fit samples, every other selected effect
refitted each time: a setting the values imply (Term.implied_setting) by fixed-point iteration (the
secant method where that fails), one independent of them (Term.search_interval) by a bounded search.

    design, chosen = refine(context, segments, design, chosen)   # a design of the chosen alone"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

from . import moments as dz
from .forward_selection import solve

REFINE_TOLERANCE = 1e-3  # relative (fixed point)
SEARCH_TOLERANCE = 0.01  # in the logarithm of a searched setting: 1 %
MAX_ITERATIONS = 30


def refine(context, segments, design, chosen):
    if not any(c.effect.refinable for c in chosen):
        return design, chosen
    state = _State(context, segments, design, _renumbered(chosen))
    # Settings that enter other effects' columns first (a lag, gains, a payload, a tilt).
    for index in sorted(range(len(state.chosen)), key=lambda i: not state.chosen[i].effect.shapes_others):
        if state.chosen[index].effect.refinable:
            _refine_one(state, index)
    return state.design, state.chosen


def restricted(context, segments, design, chosen):
    """The design of the chosen alone on the segments' current masks, weighted as `design`; renumbered."""
    state = _State(context, segments, design, _renumbered(chosen))
    return state.design, state.chosen


class _State:
    """The chosen candidates, their columns per segment and their restricted design."""

    def __init__(self, context, segments, design, chosen):
        self.context, self.segments, self.weights = dz.as_chosen(context, chosen), segments, design.weights
        self.template, self.chosen = design, chosen
        self.columns = self.all_columns(chosen, self.context)
        self.design = self.restricted(chosen, self.columns)

    def all_columns(self, chosen, context) -> list:
        effects = list({c.effect.key: c.effect for c in chosen}.values())
        return [dz.effect_columns(effects, context, seg) for seg in self.segments]

    def values(self, index) -> np.ndarray:
        return dz.split_values(self.chosen, solve(self.design, self.chosen).x)[index]

    def trial(self, index, setting):
        """(chosen, columns, design, context) with candidate `index` at another setting."""
        old = self.chosen[index]
        effect = old.effect.at(setting)
        chosen = self.chosen[:index] + [dz.Candidate(effect, old.joint, old.start, old.size)] + self.chosen[index + 1:]
        if effect.shapes_others:  # other effects' columns change with it (design.as_chosen)
            context = dz.as_chosen(self.context, chosen)
            columns = self.all_columns(chosen, context)
            return chosen, columns, self.restricted(chosen, columns), context
        # a per-joint candidate's columns on its own joint only, unless another joint's
        # candidate has the same setting (and key)
        joint = None if any(c.effect.key == effect.key and c.joint != old.joint for c in chosen) else old.joint
        columns = [{**cols, effect.key: dz.columns_of(effect, self.context, seg, joint)}
                   for cols, seg in zip(self.columns, self.segments)]
        return chosen, columns, self.updated(chosen, columns, index), self.context

    def updated(self, chosen, columns, index):
        """self.design with candidate `index`'s rows and columns recomputed (the others' moments do not change)."""
        cand = chosen[index]
        new = cand.slots
        design = self.design
        moments = [dz.Moments(m.G.copy(), m.b.copy(), m.c.copy(), m.count)
                   for m in (design.fit, design.select, design.test, *design.groups)]
        joints = range(self.weights.size) if cand.joint is None else [cand.joint]
        for m in moments:
            for j in joints:
                m.G[j][new, :] = 0.0
                m.G[j][:, new] = 0.0
                m.b[j][new] = 0.0
        for seg, cols in zip(self.segments, columns):
            # every role's sums at once: its mask (as 0/1 rows) times per-sample products
            masks = np.array([seg.fit, seg.select, seg.test, *_groups(seg, design)], dtype=float)
            for j in joints:
                acting = [c for c in chosen if c.joint is None or c.joint == j]
                A, slots = dz.joint_matrix(acting, cols, j)
                B = cols[cand.effect.key][:, j, :]
                k = B.shape[1]
                cross = (masks @ (A[:, :, None] * B[:, None, :]).reshape(len(B), -1)).reshape(len(masks), -1, k)
                own = (masks @ (B[:, :, None] * B[:, None, :]).reshape(len(B), -1)).reshape(len(masks), k, k)
                rhs = masks @ (B * seg.residual[:, j, None])
                for m, c, o, b in zip(moments, cross, own, rhs):
                    m.G[j][np.ix_(slots, new)] += c
                    m.G[j][np.ix_(new, slots)] += c.T
                    m.G[j][np.ix_(new, new)] -= o  # counted twice above
                    m.b[j][new] += b
        return type(self.template)(chosen, *moments[:3], self.weights, moments[3:])

    def accept(self, trial):
        self.chosen, self.columns, self.design, self.context = trial

    def snapshot(self):
        return self.chosen, self.columns, self.design, self.context

    def restricted(self, chosen, columns):
        """Moments of the chosen candidates only, weighted as the selection's design."""
        n = self.weights.size
        size = sum(c.size for c in chosen)
        fit, select, test = dz.empty(n, size), dz.empty(n, size), dz.empty(n, size)
        groups = [dz.empty(n, size) for _ in self.template.groups]
        for seg, cols in zip(self.segments, columns):
            roles = [(fit, seg.fit), (select, seg.select), (test, seg.test), *zip(groups, _groups(seg, self.template))]
            dz.add_segment(roles, chosen, cols, seg)
        return type(self.template)(chosen, fit, select, test, self.weights, groups)


def _refine_one(state, index) -> None:
    effect = state.chosen[index].effect
    if effect.implied_setting(state.values(index)) is not None:
        start = state.snapshot()
        for _ in range(MAX_ITERATIONS):
            current = state.chosen[index].effect
            values = state.values(index)
            setting = current.implied_setting(values)
            if setting is None:
                return
            if not current.plausible(values):
                break
            state.accept(state.trial(index, setting))
            if _settled(setting, current.setting, current):
                return
        # values no effect can have, or no fixed point found: a setting the data do not determine
        # (a sensor gain on a joint with little torque ran off to 14); it stays as selected,
        # unless a secant search finds the fixed point
        state.accept(start)
        if np.ndim(effect.setting) == 0:
            _secant(state, index)
        return
    joint = state.chosen[index].joint
    beside = tuple(c.effect for i, c in enumerate(state.chosen)
                   if i != index and joint is not None and c.joint == joint)
    interval = effect.search_interval(state.values(index), beside)
    if interval is None:
        return

    def cost(setting):
        chosen, _, design, _ = state.trial(index, setting)
        fit = solve(design, chosen, covariance=False)
        return float(design.weights ** 2 @ design.fit.mse(fit.slots, fit.x))

    # Searched in the logarithm of the setting (a velocity scale matters by its ratio).
    lo, hi = np.log(interval[0]), np.log(interval[1])
    best = minimize_scalar(lambda u: cost(float(np.exp(u))), bounds=(lo, hi), method="bounded",
                           options={"xatol": SEARCH_TOLERANCE})
    state.accept(state.trial(index, float(np.exp(best.x))))


def _secant(state, index) -> None:
    """The fixed point s = implied(s) by the secant method, where the plain iteration overshoots further
    each step (a sensor gain on a wrist joint beside a heavy payload: the payload's torque, scaled by
    1 + g0, moves the fitted gain by more than g0 moved). Kept only if it converges with plausible
    values."""
    start = state.snapshot()

    def excess(setting):
        state.accept(state.trial(index, setting))
        current = state.chosen[index].effect
        values = state.values(index)
        implied = current.implied_setting(values)
        return None if implied is None or not current.plausible(values) else float(implied) - setting

    s0 = float(state.chosen[index].effect.setting)
    f0 = excess(s0)
    s1 = s0 + f0 if f0 is not None else None
    f1 = excess(s1) if s1 is not None else None
    for _ in range(MAX_ITERATIONS):
        if f0 is None or f1 is None or f1 == f0:
            break
        s2 = s1 - f1 * (s1 - s0) / (f1 - f0)
        f2 = excess(s2)
        if f2 is not None and _settled(s2, s1, state.chosen[index].effect):
            state.accept(state.trial(index, s2 + f2))
            return
        s0, f0, s1, f1 = s1, f1, s2, f2
    state.accept(start)


def _settled(setting, before, effect) -> bool:
    """A fixed-point step below REFINE_TOLERANCE of the setting, or the effect's own tolerance."""
    step = float(np.linalg.norm(np.subtract(setting, before)))
    return step <= max(REFINE_TOLERANCE * float(np.linalg.norm(setting)), effect.tolerance)


def _renumbered(chosen) -> list:
    """The chosen candidates with consecutive slots (a design of these alone)."""
    out, start = [], 0
    for c in chosen:
        out.append(dz.Candidate(c.effect, c.joint, start, c.size))
        start += c.size
    return out


def _groups(seg, design) -> list:
    """The segment's block-group masks where the design keeps group moments."""
    return (seg.groups or [np.zeros(seg.residual.shape[0], dtype=bool)] * len(design.groups)) if design.groups else []
