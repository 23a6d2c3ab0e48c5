"""The consistent fit of given normal equations, by the extraction's own solver:

    min_{s, f}  x^T G x - 2 x^T g  +  lambda || pi(s) - pi(prior) ||^2_D,   x = (pi(s), f)
    s.t.  every link consistent, the YAML's bounds and total mass; signs of the friction values

The free friction values minimised in closed form leave the extraction's cost || R pi - v ||^2;
the signs are an active set around it (docs/measured-data.md). lambda is relative to unit-norm columns."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..description.robot import LinkValues
from ..extraction import driver
from ..extraction.problem import Options as ExtractOptions
from ..extraction.problem import Stage, build_problem
from ..extraction.targets import Target
from ..parameters import PER_LINK
from .columns import BOUNDED


def generators(labels, r: int, V, cone) -> np.ndarray:
    """M with natural values = M generator weights (identity but for the joints in cone)."""
    M = np.eye(r + len(labels))
    index = {lab: r + k for k, lab in enumerate(labels)}
    for (kind, j), k in index.items():
        if kind == "coulomb" and ("viscous", j) in index and j in cone:
            M[:, k] = 0  # the weight of (Fc, Fv) = beta (V, -1); the viscous column is alpha (0, 1)
            M[k, k] = V[j]
            M[index[("viscous", j)], k] = -1.0
    return M


def signs(G, g, r: int, bounded: np.ndarray) -> np.ndarray:
    """The free set of the friction weights with only their signs imposed: the driver's starting guess."""
    free = np.ones(G.shape[0] - r, dtype=bool)
    ridge = 1e-12 * np.eye(G.shape[0])
    for _ in range(20):  # rounds of the active set
        idx = np.r_[np.arange(r), r + np.flatnonzero(free)]
        x = np.zeros(G.shape[0])
        x[idx] = np.linalg.lstsq(G[np.ix_(idx, idx)] + ridge[np.ix_(idx, idx)], g[idx], rcond=None)[0]
        negative = free & bounded & (x[r:] < 0)
        if negative.any():
            free &= ~negative
            continue
        wants = (~free) & bounded & ((G @ x - g)[r:] < 0)
        if not wants.any():
            break
        free |= wants
    return free


class Solver:
    """The reduced problems of one identification: the extraction's problem and driver, built once."""

    def __init__(self, robot, model, folder, options, r: int, V, prior):
        self.model, self.options, self.r, self.V = model, options, r, V
        self.extract_options = ExtractOptions(restarts=options.restarts, seed=options.seed, threads=options.threads,
                                              global_algorithm="none", margin=options.margin)
        described = robot_with_default_bounds(robot)
        if prior is not None:
            links = np.asarray(prior, dtype=float).reshape(-1, PER_LINK)
            described = replace(described, nominal=tuple(LinkValues.from_tuple(row) for row in links))
        self.problem = build_problem(described, self.extract_options)
        self.exe = driver.build(folder)
        self.pi_prior = model("pi_full", prior) if prior is not None else None

    def solve(self, gram, rhs, labels, lam: float, restarts=None, free=None, cone=()):
        """(x = (pi, natural friction values), free set, extraction result); cone: joints held dissipative."""
        r = self.r
        M = generators(labels, r, self.V, cone)
        gram, rhs = M.T @ gram @ M, M.T @ rhs
        scale = np.sqrt(np.maximum(np.diag(gram), 0.0))
        scale = np.where(scale > 0, scale, 1.0)
        G, g = gram / np.outer(scale, scale), rhs / scale
        if lam > 0 and self.pi_prior is not None:
            G[:r, :r] += lam * np.eye(r)
            g[:r] += lam * self.pi_prior * scale[:r]
        nf = len(labels)
        bounded = np.array([kind in BOUNDED for kind, _ in labels], dtype=bool)
        free = signs(G, g, r, bounded) if free is None or free.size != nf else free.copy()
        # cross-validation solves need the fit only: one restart (the problem is convex), 150 Newton
        # steps (converged to ~1e-5 of the cost), no nearest-to-prior step (it does not change the fit)
        opts = self.extract_options if restarts is None else replace(self.extract_options, restarts=restarts,
                                                                        local_maxeval=150)
        y_f = np.zeros(nf)
        for _ in range(self.options.max_rounds):
            fi = r + np.flatnonzero(free)
            Lf = np.linalg.cholesky(G[np.ix_(fi, fi)] + 1e-12 * np.eye(len(fi)))
            X = np.linalg.solve(Lf, G[np.ix_(fi, np.arange(r))])
            xg = np.linalg.solve(Lf, g[fi])
            Ls = np.linalg.cholesky(G[:r, :r] - X.T @ X + 1e-12 * np.eye(r))  # the Schur complement
            h = g[:r] - X.T @ xg
            # cost(y) = || Ls^T y - Ls^-1 h ||^2 + const, y = scale pi
            stage = Stage("identify", [Target("full", Ls.T * scale[:r][None, :], np.linalg.solve(Ls, h))],
                          np.ones(self.problem.lower.size, dtype=bool), self.problem.reference.copy(),
                          nearest=restarts is None)
            result = driver.run(self.exe, self.problem, stage, opts)
            if result.status != "ok":
                raise RuntimeError("consistent identification: no parameters satisfy the bounds and total mass")
            pi = self.model("pi_full", result.p)
            y = pi * scale[:r]
            y_f = np.zeros(nf)
            y_f[free] = np.linalg.solve(Lf.T, xg - X @ y)
            negative = free & bounded & (y_f < 0)
            if negative.any():
                free &= ~negative
                continue
            wants = (~free) & bounded & ((G[r:, :r] @ y + G[r:, r:] @ y_f - g[r:]) < -1e-10)
            if not wants.any():
                break
            free |= wants
        return np.concatenate([pi, M[r:, r:] @ (y_f / scale[r:])]), free, result  # friction's natural values


def robot_with_default_bounds(robot):
    """The YAML's bounds, or wide ones (consistency does the real work)."""
    if robot.lower is not None:
        return robot
    lo = LinkValues(1e-3, (-2.0, -2.0, -2.0), (0.0, -100.0, -100.0, 0.0, -100.0, 0.0))
    hi = LinkValues(1000.0, (2.0, 2.0, 2.0), (100.0, 100.0, 100.0, 100.0, 100.0, 100.0))
    return replace(robot, lower=(lo,) * robot.dof, upper=(hi,) * robot.dof)
