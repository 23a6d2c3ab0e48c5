"""Physically consistent identification with friction: the extraction's convex problem with the
data's cost.

    min_{s, f}  || Y pi(s) + F f - tau ||_W^2     (W: rows scaled by 1 / sigma_joint)
    s.t.  every link consistent (pseudo-inertia positive definite, with the extraction's margin),
          the YAML's bounds and total mass, Fc >= 0, Fv >= 0, Ia >= 0 (offsets free)

pi(s) are the full base coefficients (linear in the standard parameters s), F the per-joint
friction columns [tanh(qd_j / vs_j), qd_j, 1, qdd_j] (Coulomb with a fitted smoothing velocity
vs_j, viscous, offset, rotor inertia where the rigid body does not already carry it).

One solver, not two. The cost is quadratic in (pi, f); for the friction values that are free
(not held at their bound 0) it is minimised in closed form, which leaves a quadratic in pi
alone, || R pi - v ||^2 + const with R the Cholesky factor of the Schur complement of the Gram
matrix. That is exactly the extraction's cost || W pi(s) - v ||^2, so the extraction's barrier
Newton method (templates/extract/barrier.cpp.j2) solves it unchanged. Positivity of friction is
an active set around it (Lawson-Hanson): a friction value that comes out negative is held at 0,
one held at 0 whose gradient asks to grow is freed again; a handful of rounds at most.

Weights and uncertainty come from the unconstrained fit of the same columns (ordinary least
squares): sigma_j is the RMS of joint j's residual, the standard deviations are those of the
weighted fit (uncorrelated residuals assumed: lower bounds for filtered signals), and a
coefficient is "not excited" as in least_squares.fit.

Public entry point: identify_consistent(robot, model, folder, signals, options) -> Consistent.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..extraction import driver
from ..extraction.problem import Options as ExtractOptions
from ..extraction.problem import Stage, build_problem, consistency_margin
from ..extraction.targets import Target
from ..parameters import PER_LINK
from .least_squares import fit as ols_fit

FRICTION_KINDS = ("coulomb", "viscous", "offset", "armature", "stribeck")
NONNEGATIVE = {"coulomb", "viscous", "armature", "stribeck"}
STRIBECK_VELOCITY = 0.3  # rad/s: Fs tanh(qd / vs) exp(-(qd / STRIBECK_VELOCITY)^2), static excess
SMOOTHING_GRID = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1)  # rad/s, candidates for vs_j


@dataclass
class ConsistentOptions:
    friction: tuple = FRICTION_KINDS  # which per-joint columns to include
    smoothing: float | None = None  # fixed vs for every joint; None: chosen per joint on the fit data
    margin: float = 1e-7  # consistency margin [kg m^2], as the extraction's
    restarts: int = 4
    seed: int = 1
    threads: int = 0
    max_rounds: int = 8  # active-set rounds for the sign constraints on friction
    weighted: bool = True  # rows scaled by 1 / sigma_joint
    nonnegative: frozenset = frozenset(NONNEGATIVE)
    prior: np.ndarray | None = None  # dynamic parameters (10N) to regularise toward (and the reference)
    regularisation: float = 0.0  # weight of || pi - pi(prior) ||^2 in unit-norm columns (~ samples' worth)


@dataclass
class Consistent:
    """The result: full link parameters, friction per joint, and the statistics of the fit."""

    p: np.ndarray  # dynamic parameters (10N), physically consistent
    pi: np.ndarray  # full base coefficients of p
    names: list  # base coefficient expressions (standard parameters)
    friction: dict  # kind -> (N,) values (nan where the column is not used)
    smoothing: np.ndarray  # (N,) vs_j [rad/s]
    sigma: np.ndarray  # (N,) per-joint noise estimate used as weight [Nm]
    ols: object  # least_squares.Estimate of the unconstrained weighted fit (coefficients, then friction)
    column_names: list  # names of the OLS columns
    residual_rms: np.ndarray  # (N,) RMS of the consistent model's residual on the fit data
    ols_residual_rms: np.ndarray  # (N,) the same for the unconstrained fit
    lambda_min: np.ndarray  # (N,) consistency margin of each link
    rounds: int
    extraction_cost: float
    dropped_armature: list = field(default_factory=list)  # joints whose rotor inertia the body carries
    at_bounds: list = field(default_factory=list)  # parameter names pinned at a bound

    def joint_dynamics(self) -> list:
        """Per joint {"damping", "friction", "armature"} for the URDF/MJCF writers."""
        out = []
        for j in range(len(self.sigma)):
            out.append({"damping": _nz(self.friction["viscous"][j]), "friction": _nz(self.friction["coulomb"][j]),
                        "armature": _nz(self.friction["armature"][j])})
        return out

    def predict(self, model, signals) -> np.ndarray:
        """Torques (T, N) of this model (rigid body + friction + offset + rotor inertia) on signals."""
        Y = model.batch("regressor", signals.q, signals.qd, signals.qdd)
        tau = Y @ self.pi
        f = self.friction
        tau = tau + np.nan_to_num(f["coulomb"]) * np.tanh(signals.qd / self.smoothing)
        tau = tau + np.nan_to_num(f["viscous"]) * signals.qd + np.nan_to_num(f["offset"])
        tau = tau + np.nan_to_num(f["stribeck"]) * np.tanh(signals.qd / self.smoothing) * np.exp(
            -(signals.qd / STRIBECK_VELOCITY) ** 2)
        return tau + np.nan_to_num(f["armature"]) * signals.qdd


def _nz(x) -> float:
    return 0.0 if not np.isfinite(x) else float(x)


# ---------------------------------------------------------------------------------------------
# the design: base regressor and friction columns


def _friction_columns(signals, kinds, smoothing, armature_ok) -> tuple[list, list]:
    """Columns (rows = samples x joints, in the regressor's row order) and their (kind, joint)."""
    n = signals.q.shape[1]
    cols, labels = [], []
    T = signals.q.shape[0]
    for j in range(n):
        for kind in kinds:
            if kind == "armature" and not armature_ok[j]:
                continue
            col = np.zeros((T, n))
            if kind == "coulomb":
                col[:, j] = np.tanh(signals.qd[:, j] / smoothing[j])
            elif kind == "viscous":
                col[:, j] = signals.qd[:, j]
            elif kind == "offset":
                col[:, j] = 1.0
            elif kind == "stribeck":
                v = signals.qd[:, j]
                col[:, j] = np.tanh(v / smoothing[j]) * np.exp(-(v / STRIBECK_VELOCITY) ** 2)
            else:
                col[:, j] = signals.qdd[:, j]
            cols.append(col.reshape(-1))
            labels.append((kind, j))
    return cols, labels


def identifiable_armature(model, dof: int, seed: int = 0) -> list[bool]:
    """Whether joint j's rotor inertia Ia_j qdd_j is independent of the rigid-body base columns
    (joint 1's is not: the first link's inertia about axis 1 enters alone, the same way)."""
    rng = np.random.default_rng(seed)
    states = 40
    q, qd, qdd = (rng.uniform(-2, 2, (states, dof)) for _ in range(3))
    Y = model.batch("regressor", q, qd, qdd).reshape(states * dof, -1)
    ok = []
    for j in range(dof):
        col = np.zeros((states, dof))
        col[:, j] = qdd[:, j]
        col = col.reshape(-1)
        x, *_ = np.linalg.lstsq(Y, col, rcond=None)
        ok.append(bool(np.linalg.norm(Y @ x - col) > 1e-8 * np.linalg.norm(col)))
    return ok


def _design(model, signals_list, kinds, smoothing, armature_ok):
    Ys, Fs, taus = [], [], []
    labels = None
    for s in signals_list:
        Y = model.batch("regressor", s.q, s.qd, s.qdd)
        Ys.append(Y.reshape(-1, Y.shape[-1]))
        cols, labels = _friction_columns(s, kinds, smoothing, armature_ok)
        Fs.append(np.column_stack(cols) if cols else np.zeros((Ys[-1].shape[0], 0)))
        taus.append(np.asarray(s.tau).reshape(-1))
    return np.vstack(Ys), np.vstack(Fs), np.concatenate(taus), labels


def _choose_smoothing(model, signals_list, kinds, armature_ok, dof) -> np.ndarray:
    """Per joint, the vs of SMOOTHING_GRID whose unconstrained fit leaves joint j the least
    residual (all joints at the same candidate; the columns of a joint barely move the others)."""
    if "coulomb" not in kinds:
        return np.full(dof, SMOOTHING_GRID[0])
    best = np.full(dof, np.inf)
    choice = np.full(dof, SMOOTHING_GRID[0])
    for vs in SMOOTHING_GRID:
        Y, F, tau, _ = _design(model, signals_list, kinds, np.full(dof, vs), armature_ok)
        A = np.hstack([Y, F])
        x, *_ = np.linalg.lstsq(A / np.linalg.norm(A, axis=0).clip(1e-300), tau, rcond=None)
        r = (tau - (A / np.linalg.norm(A, axis=0).clip(1e-300)) @ x).reshape(-1, dof)
        ms = np.mean(r ** 2, axis=0)
        better = ms < best
        best[better], choice[better] = ms[better], vs
    return choice


# ---------------------------------------------------------------------------------------------
# the fit


def identify_consistent(robot, model, folder, signals_list, options: ConsistentOptions | None = None,
                        on_progress=None) -> Consistent:
    """robot: description (bounds, total mass, nominal); model: runtime.load of its generated
    folder `folder` (which holds <robot>_extract.cpp); signals_list: conditioned recordings."""
    options = options or ConsistentOptions()
    dof = robot.dof
    names = [e["standard"] for e in model.manifest["coefficients"]["full"]["expressions"]]
    kinds = tuple(k for k in FRICTION_KINDS if k in options.friction)
    armature_ok = identifiable_armature(model, dof) if "armature" in kinds else [False] * dof
    smoothing = (np.full(dof, float(options.smoothing)) if options.smoothing
                 else _choose_smoothing(model, signals_list, kinds, armature_ok, dof))
    Y, F, tau, labels = _design(model, signals_list, kinds, smoothing, armature_ok)
    r = Y.shape[1]
    joint_of_row = np.arange(Y.shape[0]) % dof

    # Unconstrained fit: per-joint noise (the weights), then the weighted fit's statistics.
    A = np.hstack([Y, F])
    column_names = names + [f"{kind} j{j + 1}" for kind, j in labels]
    first = ols_fit(A, tau, column_names)
    res = (tau - A @ first.values).reshape(-1, dof)
    sigma = np.sqrt(np.mean(res ** 2, axis=0)) if options.weighted else np.ones(dof)
    sigma = np.maximum(sigma, 1e-6 * max(sigma.max(), 1e-12))
    w = 1.0 / sigma[joint_of_row]
    Aw, bw = A * w[:, None], tau * w
    ols = ols_fit(Aw, bw, column_names)
    ols_rms = np.sqrt(np.mean(((tau - A @ ols.values).reshape(-1, dof)) ** 2, axis=0))

    # Gram matrix of the scaled weighted columns: everything after this is small.
    scale = np.linalg.norm(Aw, axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    As = Aw / scale
    G = As.T @ As
    g = As.T @ bw
    bb = float(bw @ bw)

    problem_options = ExtractOptions(restarts=options.restarts, seed=options.seed, threads=options.threads,
                                     global_algorithm="none", margin=options.margin)
    bounded_robot = robot_with_default_bounds(robot)
    if options.prior is not None:
        from dataclasses import replace

        from ..description.robot import LinkValues

        links = np.asarray(options.prior, dtype=float).reshape(-1, PER_LINK)
        bounded_robot = replace(bounded_robot, nominal=tuple(LinkValues.from_tuple(row) for row in links))
    problem = build_problem(bounded_robot, problem_options)
    if options.prior is not None and options.regularisation > 0:
        # Tikhonov toward the prior's base coefficients, in the unit-norm columns (y = scale pi)
        y_prior = model("pi_full", np.asarray(options.prior, dtype=float)) * scale[:r]
        G = G.copy()
        G[:r, :r] += options.regularisation * np.eye(r)
        g = g.copy()
        g[:r] += options.regularisation * y_prior
    exe = driver.build(folder)

    nf = F.shape[1]
    bounded = np.array([kind in options.nonnegative for kind, _ in labels], dtype=bool)
    free = np.ones(nf, dtype=bool)
    rounds, result, f_full = 0, None, np.zeros(nf)
    for rounds in range(1, options.max_rounds + 1):
        fi = r + np.flatnonzero(free)
        pi_idx = np.arange(r)
        Gff = G[np.ix_(fi, fi)]
        Gfp = G[np.ix_(fi, pi_idx)]
        Lf = np.linalg.cholesky(Gff + 1e-14 * np.eye(len(fi)) * max(np.trace(Gff), 1.0))
        X = np.linalg.solve(Lf, Gfp)  # Lf^-1 Gfp
        xg = np.linalg.solve(Lf, g[fi])
        S = G[:r, :r] - X.T @ X  # Schur complement: the cost's Hessian in the scaled pi
        h = g[:r] - X.T @ xg
        Ls = np.linalg.cholesky(S + 1e-13 * np.trace(S) / r * np.eye(r))
        # cost(pi_scaled) = || Ls^T y - Ls^-1 h ||^2 + const, y = scale * pi
        W = Ls.T * scale[:r][None, :]
        v = np.linalg.solve(Ls, h)
        stage = Stage("identify", [Target("full", W, v)], np.ones(PER_LINK * dof, dtype=bool),
                      problem.reference.copy())
        result = driver.run(exe, problem, stage, problem_options,
                            (lambda d, t: on_progress(rounds, d, t)) if on_progress else None)
        if result.status != "ok":
            raise RuntimeError("consistent identification: no feasible parameters (bounds, total mass)")
        pi = model("pi_full", result.p)
        y_pi = pi * scale[:r]
        # friction values that minimise the cost for this pi
        f_scaled = np.zeros(nf)
        f_scaled[free] = np.linalg.solve(Lf.T, xg - X @ y_pi)
        negative = free & bounded & (f_scaled < 0)
        if negative.any():
            free &= ~negative
            continue
        grad = 2 * (G[r:, :r] @ y_pi + G[r:, r:] @ f_scaled - g[r:])
        wants = (~free) & bounded & (grad < -1e-9 * max(1.0, abs(bb)))
        if not wants.any():
            break
        free |= wants
    f_full = f_scaled / scale[r:]
    friction = {k: np.full(dof, np.nan) for k in FRICTION_KINDS}
    for (kind, j), value in zip(labels, f_full):
        friction[kind][j] = value
    for kind in kinds:
        friction[kind] = np.where(np.isnan(friction[kind]), 0.0, friction[kind]) if kind != "armature" else \
            np.where(np.array(armature_ok), np.nan_to_num(friction[kind]), np.nan)
    pred = Y @ pi + F @ f_full
    rms = np.sqrt(np.mean(((tau - pred).reshape(-1, dof)) ** 2, axis=0))
    lam = np.array([consistency_margin(row) for row in result.p.reshape(-1, PER_LINK)])
    return Consistent(result.p, pi, names, friction, smoothing, sigma, ols, column_names, rms, ols_rms, lam,
                      rounds, float(result.cost), [j + 1 for j in range(dof) if not armature_ok[j]],
                      pinned(problem, result.p))


def pinned(problem, p, rel: float = 1e-6) -> list:
    from ..parameters import dynamic_name

    span = np.maximum(problem.upper - problem.lower, 1e-300)
    at = (np.abs(p - problem.lower) < rel * span) | (np.abs(problem.upper - p) < rel * span)
    return [dynamic_name(j // PER_LINK + 1, j % PER_LINK) for j in np.flatnonzero(at)]


def robot_with_default_bounds(robot):
    """The YAML's bounds, or (none given) wide ones: a link 1 g to 1000 kg, its centre of mass
    within 2 m of its frame, inertias within +-100 kg m^2 (consistency does the real work)."""
    if robot.lower is not None:
        return robot
    from dataclasses import replace

    from ..description.robot import LinkValues

    lo = LinkValues(1e-3, (-2.0, -2.0, -2.0), (0.0, -100.0, -100.0, 0.0, -100.0, 0.0))
    hi = LinkValues(1000.0, (2.0, 2.0, 2.0), (100.0, 100.0, 100.0, 100.0, 100.0, 100.0))
    return replace(robot, lower=(lo,) * robot.dof, upper=(hi,) * robot.dof)
