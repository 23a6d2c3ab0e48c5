"""Physically consistent identification with friction: the extraction's convex problem with the
data's cost, min || Y pi(s) + F f - tau ||_W^2 + lambda || pi(s) - pi(prior) ||_D^2 over consistent
links within the YAML's bounds and mass, Fc, Fv, Ia >= 0 (W: 1 / sigma_j; F: columns.py). On the
fit recordings only: 1. the normal equations per part and joint, once (normal.py); 2. the Coulomb
smoothing and lag; 3. the weights and the columns the data cannot separate; 4. lambda and 5. the
optional groups on held-out data (held_out.py); 6. the consistent fit (solver.py); 7. the
statistics (statistics.py). docs/measured-data.md, "Excitation and physically consistent identification"."""

from __future__ import annotations

import os

import numpy as np

from ..errors import InputError
from ..extraction.problem import pinned
from ..parameters import PER_LINK, consistency_margin
from ..terms import tilt
from ..terms.body import armature_identifiable
from ..terms.friction import SIMPLE_SCALE
from . import held_out
from .blocks import Blocks, sources_of, tilt_columns, velocity_limits
from .columns import PER_JOINT, group_of, kinds_of, name_of
from .consistent_output import Consistent
from .least_squares import WEAK
from .normal import Normal, Swaps, solve_unconstrained
from .identify_options import BOUNDS, LAG_GRID, SMOOTHING_GRID, ConsistentOptions
from .solver import Solver
from .statistics import estimate


def _coulomb_search(normal, trials, fit, grid, tolerance: float):
    """Per joint, the grid value whose trial (normal with every Coulomb column at it) leaves joint j the
    least unconstrained residual on the fit parts, each beating the one before by `tolerance`
    (relative). Returns (choice per joint, normal with it)."""
    n = normal.n[fit].sum(axis=0)
    best, choice, which = np.full(normal.dof, np.inf), np.full(normal.dof, grid[0], dtype=float), np.zeros(normal.dof, int)
    for i, (value, trial) in enumerate(zip(grid, trials)):
        ms = trial.sse(solve_unconstrained(*trial.total(fit)), fit).sum(axis=0) / np.maximum(n, 1)
        better = ms < best * (1 - tolerance)
        best[better], choice[better], which[better] = ms[better], value, i
    return choice, Normal.per_joint([trials[i] for i in which])


def _at(dof, smoothing, lag):
    """make(piece): the piece's Coulomb columns at this smoothing and lag (scalars or per joint)."""
    return lambda p: p.coulomb(np.broadcast_to(smoothing, (dof,)), np.broadcast_to(lag, (dof,)))


def _coulomb(blocks, normal, fit, options, dof, ks, swaps=None):
    """Step 2: (smoothing, lags, normal) chosen per joint on the fit data unless given (ks: the Coulomb
    labels); the blocks follow."""
    smoothing, lags = blocks.smoothing, blocks.lags
    if not ks:
        return smoothing, lags, normal
    if swaps is not None:
        smoothing, normal = _coulomb_search(normal, swaps.normals(normal), fit, SMOOTHING_GRID, 0.0)
        blocks.smoothing = smoothing
    if options.friction_lag:
        zero = LAG_GRID[0] == 0.0  # the trial of no lag is the normal equations at hand: no variant for it
        trials = [normal] * zero + normal.swapped(blocks, ks, [_at(dof, smoothing, v) for v in LAG_GRID[zero:]])
        lags, normal = _coulomb_search(normal, trials, fit, LAG_GRID, 1e-3)
        blocks.lags = lags
    return smoothing, lags, normal


def _unexcited(normal, fit, weights, r) -> set:
    """Labels (indices) the weighted fit cannot tell from the rest: while the unit-norm columns have a
    direction weaker than WEAK, the label carrying most of it goes (coefficients the data do not
    excite are left to the prior and consistency)."""
    G, _ = normal.total(fit, weights)
    norms = np.sqrt(np.maximum(np.diag(G), 0.0))
    out = {k - r for k in range(r, G.shape[0]) if norms[k] == 0}
    while True:
        keep = [k for k in range(G.shape[0]) if k < r or k - r not in out]
        scale = np.where(norms[keep] > 0, norms[keep], 1.0)  # a column of zeros stays zero
        ev, V = np.linalg.eigh(G[np.ix_(keep, keep)] / np.outer(scale, scale))
        if ev[0] > WEAK ** 2 * ev[-1]:
            return out
        labels_at = [i for i, k in enumerate(keep) if k >= r]
        weakest = V[:, 0] ** 2
        if not labels_at or max(weakest[labels_at]) < 0.05:  # among the coefficients only
            return out
        out.add(keep[max(labels_at, key=lambda i: weakest[i])] - r)


def identify_consistent(robot, model, folder, signals_list, options: ConsistentOptions | None = None,
                        select=None) -> Consistent:
    """robot: its description; model: runtime.load of its generated folder `folder` (with
    <robot>_extract.cpp); signals_list: conditioned recordings with torques, or blocks.Source;
    select: the same to make the held-out choices on (default: cross-validation over the fit's parts)."""
    options = options or ConsistentOptions()
    if options.friction_bound not in BOUNDS:
        raise ValueError(f"friction_bound {options.friction_bound!r}: expected one of {', '.join(BOUNDS)}")
    dof = robot.dof
    names = [e["standard"] for e in model.manifest["coefficients"]["full"]["expressions"]]
    r = len(names)
    prior = options.prior
    if prior is None and robot.nominal is not None:
        prior = np.array([v for link in robot.nominal for v in link.as_tuple()])
    forced = set(kinds_of(options.friction))
    optional = set(kinds_of(g for g in options.candidates if g != "tilt")) - forced
    kinds = tuple(k for k in PER_JOINT if k in forced | optional)
    g_vec = tilt.gravity_of(robot)
    tilt_mode = options.tilt if options.tilt is not None else ("auto" if "tilt" in options.candidates else False)
    with_tilt = bool(tilt_mode) and prior is not None and g_vec is not None
    sources, select_sources = sources_of(signals_list, options.block_rows), sources_of(select or [], options.block_rows)
    rows = dof * sum(s.rows for s in sources)
    unknowns = r + len(kinds_of(options.friction)) * dof
    if rows <= 2 * unknowns:  # before anything is compiled or solved
        raise InputError(", ".join(s.name for s in sources), "",
                         f"under-determined: {rows} equations for {unknowns} coefficients and friction values; "
                         f"record at least {2 * unknowns // dof + 1} samples (many more, on an exciting trajectory, "
                         "for a usable estimate)")
    armature_ok = armature_identifiable(model, dof) if "armature" in kinds else [False] * dof
    labels = [(kind, j) for j in range(dof) for kind in kinds if kind != "armature" or armature_ok[j]] \
        + ([("tilt", 0), ("tilt", 1)] if with_tilt else [])

    # 1. regressor, columns and normal equations per part and joint
    folds = max(2, int(options.folds))
    parts = folds + (1 if select else 0)
    fit = list(range(folds))
    blocks = Blocks(model, sources + select_sources, [(folds,)] * len(sources) + [folds] * len(select_sources), labels,
                    np.full(dof, float(options.smoothing or SIMPLE_SCALE)), np.zeros(dof),
                    lambda q: tilt.gravity_matrix(robot, prior, q), g_vec)
    ks = [k for k, (kind, _) in enumerate(labels) if kind == "coulomb"]
    swaps = None  # 2. the Coulomb term's smoothing: every value of its grid summed in the same pass
    if ks and options.smoothing is None:
        swaps = Swaps(labels, r, parts, dof, ks, [_at(dof, v, 0.0) for v in SMOOTHING_GRID], int(with_tilt))
    normal = Normal.build(blocks, labels, r, parts, dof, swaps, int(with_tilt))
    smoothing, lags, normal = _coulomb(blocks, normal, fit, options, dof, ks, swaps)

    # 3. noise per joint, weights; columns the data cannot separate
    n_fit = normal.n[fit].sum(axis=0)
    x0 = solve_unconstrained(*normal.total(fit))
    sigma = np.sqrt(normal.sse(x0, fit).sum(axis=0) / np.maximum(n_fit, 1)) if options.weighted else np.ones(dof)
    sigma = np.maximum(sigma, 1e-9 + 1e-6 * sigma.max())
    weights = 1.0 / sigma
    drop = _unexcited(normal, fit, weights, r)
    if any(labels[k][0] == "tilt" for k in drop):
        drop |= {k for k, lab in enumerate(labels) if lab[0] == "tilt"}
    dropped = [name_of(labels[k]) for k in sorted(drop)]
    active = [k for k in range(len(labels)) if k not in drop]

    # 4. lambda; 5. optional groups
    solver = Solver(robot, model, folder, options, r, velocity_limits(robot, sources), prior)
    workers = options.workers or min(2, os.cpu_count() or 1)
    splits = held_out.Folds.make(parts, bool(select), weights)
    # joints whose friction may fall with speed (a candidate, or all with friction_bound "dissipative")
    cone = set()
    if options.friction_bound == "dissipative" or "falling" in options.candidates:
        present = {labels[k] for k in active}
        cone = {j for j in range(dof) if ("coulomb", j) in present and ("viscous", j) in present}
    lam, table, kept = options.regularisation, [], {}
    if lam is None:
        lam = 0.0
        if prior is not None and len(options.grid) > 1:
            lam, table, kept = held_out.choose_lambda(solver, normal, splits, active, options.grid, options.rule,
                                                       workers, cone)
    undecided = [k for k in active if (labels[k][0] in optional) or (labels[k][0] == "tilt" and tilt_mode == "auto")]
    falling = cone if options.friction_bound != "dissipative" and "falling" in options.candidates else set()
    groups = []
    if undecided or falling:
        base = kept.get(lam) or held_out.scores(solver, normal, splits, active, lam, workers=workers, cone=cone)
        active, cone, groups = _decide(solver, normal, splits, active, cone, undecided, falling, base, lam, workers)

    # 6. the consistent fit on all fit data
    notes = []
    result, x, normal, active = _final(solver, normal, blocks, fit, weights, active, cone, lam, g_vec, notes, dropped)
    final_labels = [labels[k] for k in active]
    keep = np.r_[np.arange(r), r + np.asarray(active, dtype=int)]

    # 7. statistics of the same columns
    column_names = names + [name_of(lab) for lab in final_labels]
    ols = estimate(normal, fit, weights, blocks, column_names, keep, dof)
    rms = np.sqrt(normal.sse(x, fit, keep).sum(axis=0) / np.maximum(n_fit, 1))
    ols_rms = np.sqrt(normal.sse(ols.values, fit, keep).sum(axis=0) / np.maximum(n_fit, 1))

    friction = {**{k: np.full(dof, np.nan) for k in PER_JOINT}, "tilt": np.zeros(2)}
    for (kind, j), value in zip(final_labels, x[r:]):
        friction[kind][j] = value  # for the tilt, j is the direction (u1, u2)
    lam_min = np.array([consistency_margin(row) for row in result.p.reshape(-1, PER_LINK)])
    return Consistent(result.p, x[:r], names, friction, smoothing, sigma, ols, column_names, rms, ols_rms, lam_min,
                      lam, table, [j + 1 for j in range(dof) if not armature_ok[j]], pinned(solver.problem, result.p),
                      (robot, prior) if any(kind == "tilt" for kind, _ in final_labels) else None, dropped, lags,
                      groups, notes)


def _decide(solver, normal, splits, active, cone, undecided, falling, base, lam, workers):
    """Step 5: each optional group kept where it gains on held-out data by more than a standard error."""
    labels = normal.labels
    decisions, out, out_cone = [], set(active), set(cone)
    for group in ("tilt", "ripple", "falling"):
        members = [k for k in undecided if group_of(labels[k]) == group]
        if group == "falling" and falling:
            without = held_out.scores(solver, normal, splits, active, lam, workers=workers, cone=cone - falling)
            joints = sorted(falling)
        elif members:
            without = held_out.scores(solver, normal, splits, [k for k in active if k not in members], lam,
                                       workers=workers, cone=cone)
            joints = [None] if group == "tilt" else sorted({labels[k][1] for k in members})
        else:
            continue
        for j in joints:
            gain = held_out.gains(base, without, j)
            keep = held_out.keeps(gain, splits)
            decisions.append((group, None if j is None else j + 1, gain[0], gain[1], keep))
            if not keep and group == "falling":
                out_cone.discard(j)
            elif not keep:
                out -= {k for k in members if j is None or labels[k][1] == j}
    return sorted(out), out_cone, decisions


def _final(solver, normal, blocks, fit, weights, active, cone, lam, g_vec, notes, dropped):
    """Step 6: the consistent fit; a tilt refitted as a rotation, refused beyond tilt.MAX_TILT_DEG, its
    torques the prior's links' (their first moments across gravity the data cannot give)."""
    labels, r = normal.labels, normal.r

    def fit_with(act):
        G, g = normal.total(fit, weights, np.r_[np.arange(r), r + np.asarray(act, dtype=int)])
        x, _, result = solver.solve(G, g, [labels[k] for k in act], lam, cone=cone)
        return x, result

    x, result = fit_with(active)
    tilt_at = [i for i, k in enumerate(active) if labels[k][0] == "tilt"]
    if tilt_at:
        a = x[r + np.asarray(tilt_at)]
        # the estimate's columns from here on (the statistics' pass reads them): algebra on the hidden column
        normal = normal.rotated([active[i] for i in tilt_at], a / (2 * float(np.linalg.norm(g_vec))))
        blocks.tilt = tilt_columns(g_vec, a)
        x, result = fit_with(active)
        a = x[r + np.asarray(tilt_at)]
        if tilt.angle_deg(g_vec, a) > tilt.MAX_TILT_DEG:
            notes.append(f"a base tilt of {tilt.angle_deg(g_vec, a):.1f} deg was refused (above {tilt.MAX_TILT_DEG:g} "
                         "deg it is no mounting error: check the YAML's gravity and the torque signs)")
            dropped += [name_of(("tilt", 0)), name_of(("tilt", 1))]
            active = [k for k in active if labels[k][0] != "tilt"]
            x, result = fit_with(active)
    return result, x, normal, active
