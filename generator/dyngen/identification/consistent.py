"""Physically consistent identification with friction: the extraction's convex problem with the
data's cost.

    min_{s, f}  || Y pi(s) + F f - tau ||_W^2  +  lambda || pi(s) - pi(prior) ||_D^2
    s.t.  every link consistent (pseudo-inertia positive definite less the extraction's margin),
          the YAML's bounds and total mass, per joint: Fc >= 0, Fc + Fv V >= 0, Ia >= 0

pi(s) are the full base coefficients (linear in the standard parameters s); W scales the rows of
joint j by 1 / sigma_j (its noise estimate); F holds per joint the columns of Coulomb friction
tanh(qd_j / vs_j) (vs_j fitted), viscous friction qd_j, an offset 1 and rotor inertia qdd_j
(where the rigid body does not already carry it: joint 1's is part of link 1's inertia).
Friction must oppose motion at every velocity the joint can reach (|qd| <= V, its velocity limit):
Fc >= 0 and Fc + Fv V >= 0. A slightly negative Fv is allowed by that, and real joints need
it: on the LWR4+ Coulomb friction falls with speed (a Stribeck-like shape) and the fitted Fv of
joint 5 is -0.23 Nm s/rad with Fc = 1.1 Nm. The cone is spanned by two generators with
non-negative weights, (Fc, Fv) = alpha (0, 1) + beta (V, -1), so every constraint on f is a sign.

One solver, not two. The cost is quadratic in (pi, f); for the friction weights that are free
(not held at their bound 0) it is minimised in closed form, which leaves a quadratic in pi alone,
|| R pi - v ||^2 + const, R the Cholesky factor of the Gram matrix's Schur complement. That is
exactly the extraction's cost || W pi(p) - v ||^2, so the extraction's driver (its barrier Newton
method in s, templates/extract/barrier.cpp.j2) solves it unchanged, bounds, total mass and
consistency included; among equally good parameter sets it returns the one closest to the
prior (the parameters the data cannot see stay near it). The signs of the friction weights are
an active set around it (Lawson-Hanson): a weight that comes out negative is held at 0, one held
at 0 whose gradient asks to grow is freed again; two or three rounds in practice.

lambda (unit-norm columns: lambda = 1 weighs like one well-excited column's worth of data) is
chosen on held-out data: the `select` recordings, or else by cross-validation over contiguous
parts of the fit recordings (default five: each held out once), with the one-standard-error rule.
The model is then refitted on all fit data. Test data are never seen here.

Statistics come from the unconstrained weighted least squares of the same columns (the
residual per joint gives sigma_j; std and "not excited" as in least_squares.fit).

Public entry point: identify_consistent(robot, model, folder, signals, options) -> Consistent.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..arguments import real
from ..errors import InputError
from ..extraction import driver
from ..extraction.problem import Options as ExtractOptions
from ..extraction.problem import Stage, build_problem, consistency_margin
from ..extraction.targets import Target
from ..options import option
from ..parameters import PER_LINK, dynamic_name
from .least_squares import WEAK, Estimate
from .tilt import tilt_columns

FRICTION_KINDS = ("coulomb", "viscous", "offset", "armature", "ripple_cos", "ripple_sin")
DEFAULT_KINDS = ("coulomb", "viscous", "offset", "armature")
CHOICES = ("coulomb", "viscous", "offset", "armature", "ripple")  # what options.friction may name
SMOOTHING_GRID = (0.0002, 0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1)  # rad/s, candidates for vs_j
LAG_GRID = (0.0, 0.01, 0.02, 0.04)  # s, candidates for the Coulomb term's lag behind the velocity
REGULARISATION_GRID = (0.0, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0)


@dataclass
class ConsistentOptions:
    """Options of the consistent identification; those declared with option(...) are also
    `dyngen identify` flags (dyngen.options), the rest the method's own settings."""

    friction: tuple = option(DEFAULT_KINDS, "per-joint columns: " + ", ".join(CHOICES) + " (cos q_j, sin q_j)",
                             metavar="LIST", listed=True)
    smoothing: float | None = option(None, "Coulomb friction as tanh(qd / V) with this V [rad/s] on every joint "
                                     "(default: chosen per joint on the fit data)", metavar="V",
                                     parse=real(0, 100, above=True))
    margin: float = ExtractOptions.margin  # consistency margin [kg m^2]: the extraction's
    restarts: int = 2
    seed: int = 1
    threads: int = 0
    max_rounds: int = 8  # active-set rounds for the signs of the friction weights
    weighted: bool = True  # rows scaled by 1 / sigma_joint
    prior: np.ndarray | None = None  # dynamic parameters (10N); default the YAML's nominal
    regularisation: float | None = option(None, "weight of the prior (default: chosen by cross-validation over "
                                          "contiguous parts of the fit data, or on --select data)", metavar="L",
                                          parse=real(0, 1e9))  # None: chosen from REGULARISATION_GRID
    grid: tuple = REGULARISATION_GRID
    folds: int = 5  # contiguous parts for choosing the regularisation when no select data are given
    rule: str = "1se"  # "1se" (one-standard-error rule) or "min" (the best held-out score)
    # two more columns: a horizontal gravity component dg (a tilted base), prior's masses
    tilt: bool = option(False, "also fit a tilted base (a horizontal gravity component)")
    friction_lag: bool = True  # Coulomb term follows the velocity with a per-joint lag from LAG_GRID


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
    regularisation: float
    selection: list  # (lambda, held-out weighted mean square) tried
    rounds: int
    dropped_armature: list = field(default_factory=list)  # joints whose rotor inertia the body carries
    at_bounds: list = field(default_factory=list)  # parameter names pinned at a bound
    velocity_limits: np.ndarray | None = None
    tilt_model: tuple | None = None  # (robot, parameters) the tilt columns are evaluated with
    dropped_columns: list = field(default_factory=list)  # friction/tilt columns the data cannot separate
    lags: np.ndarray | None = None  # (N,) lag of the Coulomb term behind the velocity [s]

    def joint_dynamics(self) -> list:
        """Per joint {"damping", "friction", "armature"} for the URDF/MJCF writers (MuJoCo's
        damping must be >= 0: a negative Fv is left out there, and said so by the caller)."""
        f = self.friction
        return [{"damping": max(_nz(f["viscous"][j]), 0.0), "friction": _nz(f["coulomb"][j]),
                 "armature": _nz(f["armature"][j])} for j in range(len(self.sigma))]

    def predict(self, model, signals) -> np.ndarray:
        """Torques (T, N) of this model (rigid body + friction + offset + rotor inertia) on signals."""
        Y = model.batch("regressor", signals.q, signals.qd, signals.qdd)
        f = {k: np.nan_to_num(v) for k, v in self.friction.items()}
        tilt = 0.0
        if self.tilt_model is not None:
            tilt = tilt_columns(*self.tilt_model, signals.q) @ f["tilt"]
        return (tilt + Y @ self.pi + f["coulomb"] * np.column_stack([
            coulomb_column(signals, j, self.smoothing, self.lags) for j in range(len(self.sigma))]) + f["viscous"] * signals.qd
                + f["offset"] + f["armature"] * signals.qdd + f["ripple_cos"] * np.cos(signals.q)
                + f["ripple_sin"] * np.sin(signals.q))


def _nz(x) -> float:
    return 0.0 if not np.isfinite(x) else float(x)


# ---------------------------------------------------------------------------------------------
# the design: base regressor and friction columns


def identifiable_armature(model, dof: int, seed: int = 0) -> list[bool]:
    """Whether joint j's rotor inertia Ia_j qdd_j is independent of the rigid-body base columns."""
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


def _labels(kinds, armature_ok, dof) -> list:
    return [(kind, j) for j in range(dof) for kind in kinds if kind != "armature" or armature_ok[j]]


def lagged(t, x, lag: float) -> np.ndarray:
    """x(t - lag), held at x(t_0) before the start."""
    return x if lag <= 0 else np.interp(t - lag, t, x)


def coulomb_column(signals, j, smoothing, lags) -> np.ndarray:
    """tanh(qd_j(t - lag_j) / vs_j): Coulomb friction, smoothed, following the velocity with a lag."""
    lag = 0.0 if lags is None else lags[j]
    return np.tanh(lagged(signals.t, signals.qd[:, j], lag) / smoothing[j])


def _friction_matrix(signals, labels, smoothing, lags=None) -> np.ndarray:
    """Natural friction columns (rows: samples x joints, the regressor's order)."""
    T, n = signals.q.shape
    F = np.zeros((T, n, len(labels)))
    for k, (kind, j) in enumerate(labels):
        F[:, j, k] = {"coulomb": lambda: coulomb_column(signals, j, smoothing, lags), "viscous": lambda: signals.qd[:, j],
                      "offset": lambda: np.ones(T), "armature": lambda: signals.qdd[:, j],
                      "ripple_cos": lambda: np.cos(signals.q[:, j]), "ripple_sin": lambda: np.sin(signals.q[:, j])}[kind]()
    return F.reshape(T * n, len(labels))


def _design(model, signals_list, labels, smoothing, tilt=None, lags=None):
    """Y, [F | tilt columns], tau; tilt: None or (robot, prior parameters)."""
    Ys, Fs, taus, samples = [], [], [], []
    for s in signals_list:
        Y = model.batch("regressor", s.q, s.qd, s.qdd)
        Ys.append(Y.reshape(-1, Y.shape[-1]))
        F = _friction_matrix(s, [lab for lab in labels if lab[0] != "tilt"], smoothing, lags)
        if tilt is not None:
            F = np.hstack([F, tilt_columns(tilt[0], tilt[1], s.q).reshape(F.shape[0], 2)])
        Fs.append(F)
        taus.append(np.asarray(s.tau).reshape(-1))
        samples.append(s.t)
    return np.vstack(Ys), np.vstack(Fs), np.concatenate(taus)


class _Columns:
    """The unconstrained fit for many variants of the friction columns, fast: the regressor's
    Gram matrix is formed once, and a friction column of joint j only meets joint j's rows."""

    def __init__(self, model, signals_list, dof):
        self.signals, self.dof = signals_list, dof
        self.Y3 = np.concatenate([model.batch("regressor", s.q, s.qd, s.qdd) for s in signals_list])  # (T, N, r)
        self.tau = np.vstack([np.asarray(s.tau) for s in signals_list])  # (T, N)
        Y = self.Y3.reshape(-1, self.Y3.shape[2])
        self.GY, self.gY = Y.T @ Y, Y.T @ self.tau.reshape(-1)

    def residual_ms(self, labels, smoothing, lags=None) -> np.ndarray:
        """Per joint, the mean square residual of the least squares with these friction columns."""
        F = np.vstack([_friction_matrix(s, labels, smoothing, lags) for s in self.signals])
        F3 = F.reshape(self.Y3.shape[0], self.dof, -1)
        r, k = self.GY.shape[0], F.shape[1]
        G = np.zeros((r + k, r + k))
        g = np.zeros(r + k)
        G[:r, :r], g[:r] = self.GY, self.gY
        for j in range(self.dof):
            cols = np.flatnonzero(np.any(F3[:, j, :] != 0, axis=0))
            c = F3[:, j, cols]
            G[:r, r + cols] += self.Y3[:, j, :].T @ c
            G[np.ix_(r + cols, r + cols)] += c.T @ c
            g[r + cols] += c.T @ self.tau[:, j]
        G[r:, :r] = G[:r, r:].T
        scale = np.sqrt(np.maximum(np.diag(G), 1e-300))
        ev, V = np.linalg.eigh(G / np.outer(scale, scale))
        keep = ev > WEAK ** 2 * ev[-1]
        x = (V[:, keep] @ ((V[:, keep].T @ (g / scale)) / ev[keep])) / scale
        pred = self.Y3 @ x[:r] + F3 @ x[r:]
        return np.mean((self.tau - pred) ** 2, axis=0)


def _choose_smoothing(columns, labels, dof) -> np.ndarray:
    """Per joint, the vs of SMOOTHING_GRID whose unconstrained fit leaves joint j the least residual."""
    best, choice = np.full(dof, np.inf), np.full(dof, 0.02)
    for vs in SMOOTHING_GRID:
        ms = columns.residual_ms(labels, np.full(dof, vs))
        better = ms < best
        best[better], choice[better] = ms[better], vs
    return choice


def _choose_lag(columns, labels, smoothing, dof) -> np.ndarray:
    """Per joint, the lag of LAG_GRID of the Coulomb term whose unconstrained fit leaves joint j
    the least residual (like the smoothing, on the fit data)."""
    best, choice = np.full(dof, np.inf), np.zeros(dof)
    for lag in LAG_GRID:
        ms = columns.residual_ms(labels, smoothing, np.full(dof, lag))
        better = ms < best * (1 - 1e-3)  # a lag must earn its place
        best[better], choice[better] = ms[better], lag
    return choice


def _least_squares(A, b) -> np.ndarray:
    """Minimum-norm-ish least squares through the Gram matrix of unit-norm columns (pseudo-inverse
    cut at WEAK^2 of the largest eigenvalue): A has ~10^5 rows and ~10^2 columns, and forming
    A^T A once is ten times faster than an SVD or QR of A."""
    norms = np.linalg.norm(A, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    As = A / scale
    ev, V = np.linalg.eigh(As.T @ As)
    keep = ev > WEAK ** 2 * ev[-1]
    return (V[:, keep] @ ((V[:, keep].T @ (As.T @ b)) / ev[keep])) / scale


def correlation_factor(residual, dof: int, max_lag: int = 2000) -> float:
    """How much a residual correlated in time inflates the variance of least-squares estimates:
    1 + 2 sum_k rho_k (the residual's autocorrelation per joint, summed until it first drops
    below zero, Bartlett), averaged over joints. Filtered signals have correlation times of many
    samples; the textbook std (white residuals) would be too small by the square root of this."""
    r = residual.reshape(-1, dof)
    factors = []
    for j in range(dof):
        x = r[:, j] - r[:, j].mean()
        n = x.size
        spectrum = np.fft.rfft(x, 2 * n)
        acf = np.fft.irfft(spectrum * np.conj(spectrum))[:min(n, max_lag)]
        if acf[0] <= 0:
            continue
        rho = acf / acf[0]
        stop = np.flatnonzero(rho[1:] < 0)
        k = stop[0] + 1 if stop.size else rho.size
        factors.append(max(1.0, 1.0 + 2.0 * rho[1:k].sum()))
    return float(np.mean(factors)) if factors else 1.0


def _statistics(A, b, names, dof: int = 1) -> Estimate:
    """least_squares.fit's Estimate (values, std, condition numbers, unexcited) from the Gram
    matrix's eigen-decomposition: the squared singular values and right singular vectors of A."""
    rows, cols = A.shape
    norms = np.linalg.norm(A, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    As = A / scale
    G = As.T @ As
    ev, V = np.linalg.eigh(G)
    ev, V = ev[::-1], V[:, ::-1]
    sv = np.sqrt(np.maximum(ev, 0.0))
    strong = sv > WEAK * sv[0]
    x = (V[:, strong] @ ((V[:, strong].T @ (As.T @ b)) / ev[strong])) / scale
    residual = b - A @ x
    sigma2 = float(residual @ residual) / max(rows - int(strong.sum()), 1)
    loading = (V[:, ~strong].T ** 2).sum(axis=0)
    unexcited = [k for k in range(cols) if loading[k] > 0.5 or norms[k] == 0]
    std = np.sqrt(sigma2 * np.diag((V[:, strong] / ev[strong]) @ V[:, strong].T)) / scale
    std *= np.sqrt(correlation_factor(residual, dof))
    std[unexcited] = np.inf
    raw = np.sqrt(np.maximum(np.linalg.eigvalsh(A.T @ A), 0.0))
    condition = float(raw[-1] / raw[0]) if raw[0] > 0 else float("inf")
    scaled = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    return Estimate(list(names), x, std, condition, scaled, float(np.sqrt(np.mean(residual ** 2))), rows, unexcited)


def _generators(labels, r, V) -> np.ndarray:
    """M with natural = M generator weights: per joint (Fc, Fv) = alpha (0, 1) + beta (V, -1)."""
    n = r + len(labels)
    M = np.eye(n)
    index = {lab: r + k for k, lab in enumerate(labels)}
    for (kind, j), k in index.items():
        if kind == "coulomb" and ("viscous", j) in index:
            v = index[("viscous", j)]
            # generator column k now means beta (Fc = V beta, Fv gets -beta); v means alpha
            M[:, k] = 0
            M[k, k] = V[j]
            M[v, k] = -1.0
    return M


# ---------------------------------------------------------------------------------------------
# the fit


class _Solver:
    """The reduced problems for one data set: Gram matrix in generator weights, the driver."""

    def __init__(self, robot, model, folder, options, labels, r, V, prior):
        self.model, self.options, self.labels, self.r = model, options, labels, r
        self.bounded = np.array([kind in ("coulomb", "viscous", "armature") for kind, _ in labels], dtype=bool)
        self.M = _generators(labels, r, V)
        self.extract_options = ExtractOptions(restarts=options.restarts, seed=options.seed, threads=options.threads,
                                              global_algorithm="none", margin=options.margin)
        described = robot_with_default_bounds(robot)
        if prior is not None:
            from ..description.robot import LinkValues

            links = np.asarray(prior, dtype=float).reshape(-1, PER_LINK)
            described = replace(described, nominal=tuple(LinkValues.from_tuple(row) for row in links))
        self.problem = build_problem(described, self.extract_options)
        self.exe = driver.build(folder)
        self.pi_prior = model("pi_full", prior) if prior is not None else None

    def solve(self, gram, rhs, lam, restarts=None):
        """(pi, natural friction values, rounds, extraction result) for the Gram matrix A^T A and
        A^T b of the weighted rows A, b (natural columns: coefficients, then friction)."""
        r = self.r
        gram, rhs = self.M.T @ gram @ self.M, self.M.T @ rhs
        scale = np.sqrt(np.maximum(np.diag(gram), 0.0))
        scale = np.where(scale > 0, scale, 1.0)
        G, g = gram / np.outer(scale, scale), rhs / scale
        if lam > 0 and self.pi_prior is not None:
            G[:r, :r] += lam * np.eye(r)
            g[:r] += lam * self.pi_prior * scale[:r]
        nf = len(self.labels)
        free = np.ones(nf, dtype=bool)
        rounds, y_f = 0, np.zeros(nf)
        for rounds in range(1, self.options.max_rounds + 1):
            fi = r + np.flatnonzero(free)
            Gff = G[np.ix_(fi, fi)]
            Lf = np.linalg.cholesky(Gff + 1e-12 * np.eye(len(fi)))
            X = np.linalg.solve(Lf, G[np.ix_(fi, np.arange(r))])
            xg = np.linalg.solve(Lf, g[fi])
            S = G[:r, :r] - X.T @ X  # Schur complement: the cost's Hessian in the scaled pi
            h = g[:r] - X.T @ xg
            Ls = np.linalg.cholesky(S + 1e-12 * np.eye(r))
            # cost(y) = || Ls^T y - Ls^-1 h ||^2 + const, y = scale pi
            W = Ls.T * scale[:r][None, :]
            v = np.linalg.solve(Ls, h)
            stage = Stage("identify", [Target("full", W, v)], np.ones(self.problem.lower.size, dtype=bool),
                          self.problem.reference.copy())
            # cross-validation solves need the fit only: one restart (the problem is convex) and few
            # evaluations for the driver's nearest-to-prior step, which does not change the fit
            opts = self.extract_options if restarts is None else replace(self.extract_options, restarts=restarts,
                                                                            local_maxeval=150)
            result = driver.run(self.exe, self.problem, stage, opts)
            if result.status != "ok":
                raise RuntimeError("consistent identification: no parameters satisfy the bounds and total mass")
            pi = self.model("pi_full", result.p)
            y = pi * scale[:r]
            y_f = np.zeros(nf)
            y_f[free] = np.linalg.solve(Lf.T, xg - X @ y)
            negative = free & self.bounded & (y_f < 0)
            if negative.any():
                free &= ~negative
                continue
            grad = G[r:, :r] @ y + G[r:, r:] @ y_f - g[r:]
            wants = (~free) & self.bounded & (grad < -1e-10)
            if not wants.any():
                break
            free |= wants
        weights = y_f / scale[r:]
        natural = self.M[r:, r:] @ weights
        return pi, natural, rounds, result


def _folds(signals_list, folds: int):
    """Per recording, the part (0 .. folds - 1) of each sample: contiguous stretches of equal
    duration. Held-out parts are other stretches of motion, not samples interleaved with the fit
    (which the fit would predict almost as well as its own, favouring no regularisation)."""
    out = []
    for s in signals_list:
        u = (s.t - s.t[0]) / max(s.t[-1] - s.t[0], 1e-300)
        out.append(np.minimum((u * folds).astype(int), folds - 1))
    return out


def identify_consistent(robot, model, folder, signals_list, options: ConsistentOptions | None = None,
                        select=None) -> Consistent:
    """robot: description (bounds, total mass, nominal, velocity limits); model: runtime.load of
    its generated folder `folder` (which holds <robot>_extract.cpp); signals_list: conditioned
    recordings with torques to fit; select: recordings to choose lambda on (default: every third
    2-s block of the fit data)."""
    options = options or ConsistentOptions()
    dof = robot.dof
    signals_list = [_trimmed(s) for s in signals_list]
    select = [_trimmed(s) for s in select] if select else select
    names = [e["standard"] for e in model.manifest["coefficients"]["full"]["expressions"]]
    r = len(names)
    wanted = set(options.friction) | ({"ripple_cos", "ripple_sin"} if "ripple" in options.friction else set())
    kinds = tuple(k for k in FRICTION_KINDS if k in wanted)
    rows = dof * sum(len(s.t) for s in signals_list)
    unknowns = r + len(kinds) * dof + (2 if options.tilt else 0)
    if rows <= 2 * unknowns:  # before anything is compiled or solved
        raise InputError(", ".join(s.name for s in signals_list), "",
                         f"under-determined: {rows} equations for {unknowns} coefficients and friction values; "
                         f"record at least {2 * unknowns // dof + 1} samples (many more, on an exciting trajectory, "
                         "for a usable estimate)")
    armature_ok = identifiable_armature(model, dof) if "armature" in kinds else [False] * dof
    labels = _labels(kinds, armature_ok, dof)
    columns = _Columns(model, signals_list, dof) if "coulomb" in kinds else None
    smoothing = (np.full(dof, float(options.smoothing)) if options.smoothing or columns is None
                 else _choose_smoothing(columns, labels, dof))
    lags = (_choose_lag(columns, labels, smoothing, dof) if options.friction_lag and columns is not None
            else np.zeros(dof))
    V = velocity_limits(robot, signals_list)
    prior = options.prior
    if prior is None and robot.nominal is not None:
        prior = np.array([v for link in robot.nominal for v in link.as_tuple()])
    tilt = None
    if options.tilt and prior is not None:
        tilt = (robot, prior)
        labels = labels + [("tilt", 0), ("tilt", 1)]
    Y, F, tau = _design(model, signals_list, labels, smoothing, tilt, lags)

    # Unconstrained fit: per-joint noise (the weights), then the weighted fit's statistics.
    A = np.hstack([Y, F])
    column_names = names + [f"{kind} j{j + 1}" if kind != "tilt" else f"tilt dg_{'xy'[j]}" for kind, j in labels]
    res = (tau - A @ _least_squares(A, tau)).reshape(-1, dof)
    sigma = np.sqrt(np.mean(res ** 2, axis=0)) if options.weighted else np.ones(dof)
    sigma = np.maximum(sigma, 1e-9 + 1e-6 * sigma.max())
    w = np.tile(1.0 / sigma, Y.shape[0] // dof)
    Aw, bw = A * w[:, None], tau * w
    ols = _statistics(Aw, bw, column_names, dof)
    # Friction, ripple or tilt columns the data cannot tell from the rest (e.g. a ripple cos q_j,
    # sin q_j of a joint whose gravity torque has the same shape) would take arbitrary values
    # without a bound to stop them: they are left out and named.
    drop = {k - r for k in ols.unexcited if k >= r}
    if tilt is not None and any(labels[k][0] == "tilt" for k in drop):
        drop |= {k for k, lab in enumerate(labels) if lab[0] == "tilt"}
        tilt = None
    dropped = [column_names[r + k] for k in sorted(drop)]
    if drop:
        keep = [k for k in range(len(labels)) if k not in drop]
        labels = [labels[k] for k in keep]
        F = F[:, keep]
        A = np.hstack([Y, F])
        column_names = names + [column_names[r + k] for k in keep]
        Aw = A * w[:, None]
        ols = _statistics(Aw, bw, column_names, dof)
    ols_rms = np.sqrt(np.mean(((tau - A @ ols.values).reshape(-1, dof)) ** 2, axis=0))

    solver = _Solver(robot, model, folder, options, labels, r, V, prior)
    gram, rhs = Aw.T @ Aw, Aw.T @ bw
    selection = []
    lam = options.regularisation
    if lam is None:
        lam = 0.0
        if prior is not None and len(options.grid) > 1:
            # Everything through Gram matrices: a fold's fit data are all data less the fold.
            if select:
                Ys, Fs, ts = _design(model, select, labels, smoothing, tilt, lags)
                ws = np.tile(1.0 / sigma, Ys.shape[0] // dof)
                As, bs = np.hstack([Ys, Fs]) * ws[:, None], ts * ws
                folds = [((gram, rhs), (As.T @ As, As.T @ bs, float(bs @ bs), bs.size))]
            else:  # contiguous parts of every recording: each is held out once
                part = np.concatenate([np.repeat(m, dof) for m in _folds(signals_list, options.folds)])
                folds = []
                for k in range(options.folds):
                    Ak, bk = Aw[part == k], bw[part == k]
                    Gk, gk = Ak.T @ Ak, Ak.T @ bk
                    folds.append(((gram - Gk, rhs - gk), (Gk, gk, float(bk @ bk), bk.size)))
            scores = np.zeros((len(folds), len(options.grid)))
            for k, ((G_fit, g_fit), (Gk, gk, bbk, nk)) in enumerate(folds):
                for i, candidate in enumerate(options.grid):
                    # the problem is convex: one restart finds its minimum (the final fit uses more)
                    pi, f, _, _ = solver.solve(G_fit, g_fit, candidate, restarts=1)
                    x = np.concatenate([pi, f])
                    scores[k, i] = (bbk - 2 * x @ gk + x @ Gk @ x) / nk
            mean = scores.mean(axis=0)
            best = int(np.argmin(mean))
            chosen = best
            if options.rule == "1se" and len(folds) > 1:
                # the one-standard-error rule: the strongest pull toward the prior whose held-out
                # score is within one standard error of the best (a held-out part of the same
                # recording flatters the fit, so the least regularised model that "wins" there
                # generalises worse to other motions)
                se = scores[:, best].std(ddof=1) / np.sqrt(len(folds))
                chosen = max(i for i in range(len(mean)) if mean[i] <= mean[best] + se)
            selection = [(float(c), float(m)) for c, m in zip(options.grid, mean)]
            lam = float(options.grid[chosen])
    pi, f_nat, rounds, result = solver.solve(gram, rhs, lam)
    friction = {k: np.full(dof, np.nan) for k in FRICTION_KINDS}
    friction["tilt"] = np.zeros(2)
    for kind in kinds:
        friction[kind][:] = 0.0
    friction["armature"][[j for j in range(dof) if not armature_ok[j]]] = np.nan
    for (kind, j), value in zip(labels, f_nat):
        friction[kind][j] = value  # for the tilt, j is the direction (x, y)
    rms = np.sqrt(np.mean(((tau - A @ np.concatenate([pi, f_nat])).reshape(-1, dof)) ** 2, axis=0))
    lam_min = np.array([consistency_margin(row) for row in result.p.reshape(-1, PER_LINK)])
    return Consistent(result.p, pi, names, friction, smoothing, sigma, ols, column_names, rms, ols_rms, lam_min,
                      lam, selection, rounds, [j + 1 for j in range(dof) if not armature_ok[j]],
                      pinned(solver.problem, result.p), V, tilt, dropped, lags)


def _trimmed(s):
    """The recording without the filter's start-up at both ends (Signals.trim samples), which is
    not data (data/conditioning.py)."""
    k = int(getattr(s, "trim", 0) or 0)
    if k <= 0 or 2 * k >= len(s.t):
        return s
    T = len(s.t)
    cut = {name: value[k:T - k] for name, value in vars(s).items()
           if isinstance(value, np.ndarray) and value.ndim >= 1 and value.shape[0] == T}
    cut["extra"] = {name: v[k:T - k] for name, v in s.extra.items()}
    return replace(s, trim=0, **cut)


def velocity_limits(robot, signals_list) -> np.ndarray:
    """V_j: the YAML's velocity limit, or else 1.5 times the largest |qd_j| in the data."""
    seen = np.max(np.vstack([np.abs(s.qd) for s in signals_list]), axis=0)
    out = []
    for j, joint in enumerate(robot.joints):
        lim = joint.limits.velocity if joint.limits is not None and joint.limits.velocity else None
        out.append(lim if lim is not None else 1.5 * max(seen[j], 1e-3))
    return np.array(out, dtype=float)


def pinned(problem, p, rel: float = 1e-6) -> list:
    """Names of the parameters at (within rel of the range from) one of their bounds."""
    span = np.maximum(problem.upper - problem.lower, 1e-300)
    at = (np.abs(p - problem.lower) < rel * span) | (np.abs(problem.upper - p) < rel * span)
    return [dynamic_name(j // PER_LINK + 1, j % PER_LINK) for j in np.flatnonzero(at)]


def robot_with_default_bounds(robot):
    """The YAML's bounds, or (none given) wide ones: a link 1 g to 1000 kg, its centre of mass
    within 2 m of its frame, inertias within 100 kg m^2 (consistency does the real work)."""
    if robot.lower is not None:
        return robot
    from ..description.robot import LinkValues

    lo = LinkValues(1e-3, (-2.0, -2.0, -2.0), (0.0, -100.0, -100.0, 0.0, -100.0, 0.0))
    hi = LinkValues(1000.0, (2.0, 2.0, 2.0), (100.0, 100.0, 100.0, 100.0, 100.0, 100.0))
    return replace(robot, lower=(lo,) * robot.dof, upper=(hi,) * robot.dof)
