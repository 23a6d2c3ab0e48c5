"""The excitation design: a Fourier series at rest at its ends (validation.excitation.FourierTrajectory),
scaled into the limits by construction, with log cond of the identification matrix (the rigid body's
regressor and identify's default per-joint columns, terms.joint_columns) minimised over its
coefficients by L-BFGS-B from the best of `candidates` random starts, every draw from `seed`
(docs/measured-data.md, "Excitation and physically consistent identification")."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from ..description.joint_model import forward_kinematics
from ..errors import InputError
from ..options import option
from ..terms import RigidBody, joint_columns
from ..terms.body import armature_identifiable
from ..terms.friction import EXCITATION_SCALE
from ..validation.excitation import FourierTrajectory

GRID_PER_HARMONIC = 200  # samples per period of the highest harmonic for the peaks


@dataclass
class Settings:
    """The excitation step's options: those declared with option(...) are `dyngen excite` flags."""

    seed: int = option(1, "seed of every random draw", bounds=(0, 2**31 - 1))
    period: float = option(10.0, "period [s] (base frequency 1 / period)", metavar="S", bounds=(0.1, 3600))
    harmonics: int = option(5, "harmonics per joint", metavar="L", bounds=(1, 50))
    margin: float = option(0.95, "fraction of each limit the motion may use", bounds=(0.0, 1.0), above=True)
    points: int = 200  # samples of one period in the criterion
    candidates: int = 16  # random starts; the best is refined
    max_iterations: int = option(60, "optimiser (L-BFGS-B) iterations", flag="--iterations", metavar="N", bounds=(1, 100_000))
    coulomb_velocity: float = EXCITATION_SCALE  # rad/s, the Coulomb column's scale
    workspace: tuple | None = None  # (xmin, xmax, ymin, ymax, zmin, zmax) of the flange [m]
    criterion: str = option("cond", "cond: minimise the condition number; logdet: maximise log det A^T A "
                            "(columns unit norm)", choices=("cond", "logdet"))


@dataclass
class Design:
    trajectory: FourierTrajectory
    condition: float  # cond(A) on the criterion's samples
    scaled_condition: float  # with unit-norm columns
    random_condition: float  # the same for random coefficients with the same limits (median of the candidates)
    random_scaled_condition: float
    evaluations: int
    seconds: float = 0.0


@dataclass(frozen=True)
class JointLimits:
    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


def limits_of(robot) -> JointLimits:
    """The YAML's joint limits; an InputError names the first missing one."""
    values = {k: [] for k in ("lower", "upper", "velocity", "acceleration")}
    for i, joint in enumerate(robot.joints):
        for key in values:
            value = getattr(joint.limits, key, None)  # None without limits
            if value is None:
                raise InputError(robot.source, f"joints[{i}].limits.{key}",
                                 "missing (dyngen excite needs lower, upper, velocity and acceleration)")
            values[key].append(value)
    return JointLimits(*(np.array(values[k], dtype=float) for k in ("lower", "upper", "velocity", "acceleration")))


class _Shape:
    """x (vector) <-> trajectory; x = [u (N), free coefficients (N, 2 (L - 1))]."""

    def __init__(self, limits: JointLimits, settings: Settings, flange=None):
        self.limits, self.settings, self.flange = limits, settings, flange
        self.n = limits.lower.size
        self.L = settings.harmonics
        self.base_hz = 1.0 / settings.period
        self.grid = np.arange(GRID_PER_HARMONIC * self.L) / (GRID_PER_HARMONIC * self.L * self.base_hz)
        self.size = self.n + 2 * self.n * (self.L - 1)

    def random(self, rng) -> np.ndarray:
        """A random x: centres within 20 % of the range about the middle, coefficients falling as 1 / harmonic."""
        decay = np.tile(np.repeat(1.0 / np.arange(2, self.L + 1)[None, :], 2, axis=0).ravel(), self.n)
        return np.concatenate([rng.uniform(-0.2, 0.2, self.n), rng.standard_normal(self.size - self.n) * decay])

    def coefficients(self, x):
        """(a, b): the free ones for harmonics 2 .. L, the first's set so that the motion starts at rest."""
        free = x[self.n:].reshape(self.n, 2, self.L - 1)
        return (np.column_stack([-free[:, 0].sum(axis=1), free[:, 0]]),
                np.column_stack([-(free[:, 1] * np.arange(2, self.L + 1)).sum(axis=1), free[:, 1]]))

    def trajectory(self, x) -> FourierTrajectory:
        lim, m = self.limits, self.settings.margin
        centre, half = (lim.upper + lim.lower) / 2, (lim.upper - lim.lower) / 2
        q0 = centre + np.clip(x[:self.n], -0.5, 0.5) * half
        a, b = self.coefficients(x)
        q, qd, qdd = FourierTrajectory(self.base_hz, np.zeros(self.n), a, b)(self.grid)
        dev = q - q[0]  # q(0) is where the motion starts; q0 is where it starts from rest
        tiny = 1e-300
        scale = np.min([m * (lim.upper - q0) / np.maximum(dev.max(axis=0), tiny),
                        m * (q0 - lim.lower) / np.maximum(-dev.min(axis=0), tiny),
                        m * lim.velocity / np.maximum(np.abs(qd).max(axis=0), tiny),
                        m * lim.acceleration / np.maximum(np.abs(qdd).max(axis=0), tiny)], axis=0)
        scale = np.where(np.isfinite(scale), scale, 0.0)
        traj = _from(self.base_hz, q0, a * scale[:, None], b * scale[:, None])
        return self._into_box(traj, q0) if self.flange is not None and self.settings.workspace is not None else traj

    def _into_box(self, traj, q0):
        # the flange is checked on every second grid point against the box shrunk by 1 mm (the
        # written samples are checked again by the command)
        box = np.asarray(self.settings.workspace, dtype=float).reshape(3, 2) + np.array([1e-3, -1e-3])
        grid = self.grid[::2]
        if not _inside(self.flange(q0[None, :]), box).all():
            raise InputError("--workspace", "", "the flange at the trajectory's start lies outside the box")
        if _inside(self.flange(traj(grid)[0]), box).all():
            return traj
        lo, hi = 0.0, 1.0
        for _ in range(12):  # bisection on a common shrink factor of the motion about q0
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if _inside(self.flange(_shrunk(traj, q0, mid)(grid)[0]), box).all() else (lo, mid)
        return _shrunk(traj, q0, lo)


def _from(base_hz, q0, a, b) -> FourierTrajectory:
    """The series with q(0) = q0 (its value at 0 without an offset is -sum b / (w l))."""
    w = 2 * np.pi * base_hz * np.arange(1, a.shape[1] + 1)
    return FourierTrajectory(base_hz, q0 + (b / w).sum(axis=1), a, b)


def _shrunk(traj, q0, factor) -> FourierTrajectory:
    return _from(traj.base_hz, q0, traj.a * factor, traj.b * factor)


def _inside(points, box) -> np.ndarray:
    return np.all((points >= box[:, 0]) & (points <= box[:, 1]), axis=1)


def flange_of(robot):
    """q (T, N) -> flange position (T, 3) in the base frame (the last link frame's origin)."""
    return lambda q: forward_kinematics(robot.joint_models, q)[-1].origin


def identification_matrix(model, q, qd, qdd, coulomb_velocity=EXCITATION_SCALE, armature=None) -> np.ndarray:
    """[Y | per joint: tanh(qd_j / v), qd_j, 1, qdd_j (where armature[j])], rows sample-major: identify's
    default columns, each on its own joint's rows."""
    T, n = q.shape
    Y = RigidBody.regressor(model, q, qd, qdd).reshape(T * n, -1)
    cols = []
    for j in range(n):
        for kind in joint_columns.DEFAULT_KINDS:
            if kind == "armature" and not (armature and armature[j]):
                continue
            col = np.zeros((T, n))
            col[:, j] = joint_columns.column(kind, q[:, j], qd[:, j], qdd[:, j], coulomb_velocity)
            cols.append(col.reshape(-1))
    return np.hstack([Y, np.column_stack(cols)])


def _unit_columns(A) -> np.ndarray:
    norms = np.linalg.norm(A, axis=0)
    return A / np.where(norms > 0, norms, 1.0)


def _conditions(A) -> tuple[float, float]:
    sv = np.linalg.svd(A, compute_uv=False)
    svs = np.linalg.svd(_unit_columns(A), compute_uv=False)
    return (float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf, float(svs[0] / svs[-1]) if svs[-1] > 0 else np.inf)


def optimise(robot, model, settings: Settings | None = None) -> Design:
    """The optimised excitation for `robot` (its limits; the flange within settings.workspace if given)."""
    settings = settings or Settings()
    if settings.harmonics < 2:
        raise InputError("--harmonics", "", f"{settings.harmonics}: at least 2 (one is used to start at rest)")
    if settings.criterion not in ("cond", "logdet"):
        raise InputError("--criterion", "", f'expected "cond" or "logdet", got "{settings.criterion}"')
    start = time.perf_counter()
    shape = _Shape(limits_of(robot), settings, flange_of(robot) if settings.workspace is not None else None)
    armature = armature_identifiable(model, robot.dof)
    times = np.arange(settings.points) * settings.period / settings.points
    evaluations = 0

    def matrix(x):
        return identification_matrix(model, *shape.trajectory(x)(times), settings.coulomb_velocity, armature)

    def criterion(x):
        nonlocal evaluations
        evaluations += 1
        A = matrix(x)
        if settings.criterion == "logdet":
            sign, logdet = np.linalg.slogdet(_unit_columns(A).T @ _unit_columns(A))  # two operands: GEMM, not SYRK
            return -logdet if sign > 0 else 1e6
        ev = np.linalg.eigvalsh(A.T @ A)  # the Gram matrix's eigenvalues: 10 times faster than the SVD
        return float(0.5 * (np.log(max(ev[-1], 1e-300)) - np.log(max(ev[0], 1e-300))))

    rng = np.random.default_rng(settings.seed)
    starts = [shape.random(rng) for _ in range(settings.candidates)]
    values = [criterion(x) for x in starts]
    random_index = int(np.argsort(values)[len(values) // 2])  # the median random trajectory
    best = starts[int(np.argmin(values))]
    bounds = [(-0.5, 0.5)] * robot.dof + [(None, None)] * (shape.size - robot.dof)
    result = minimize(criterion, best, method="L-BFGS-B", bounds=bounds,
                      options={"maxiter": settings.max_iterations, "eps": 1e-6})
    x = result.x if result.fun <= min(values) else best
    return Design(shape.trajectory(x), *_conditions(matrix(x)), *_conditions(matrix(starts[random_index])), evaluations,
                  time.perf_counter() - start)


def random_design(robot, settings: Settings, seed: int) -> FourierTrajectory:
    """A random trajectory of the same family and limits (the comparison for a design)."""
    shape = _Shape(limits_of(robot), settings)
    return shape.trajectory(shape.random(np.random.default_rng(seed)))


def check_limits(robot, t, q, qd, qdd, workspace=None, tolerance: float = 1e-9) -> list[str]:
    """Every violated limit on the samples, the flange's workspace box included (empty: all respected)."""
    lim = limits_of(robot)
    problems = []
    for name, bad in (("lower", q < lim.lower - tolerance), ("upper", q > lim.upper + tolerance),
                      ("velocity", np.abs(qd) > lim.velocity + tolerance),
                      ("acceleration", np.abs(qdd) > lim.acceleration + tolerance)):
        for j in np.flatnonzero(bad.any(axis=0)):
            problems.append(f"joint {j + 1}: {name} limit exceeded at t = {t[np.argmax(bad[:, j])]:.4g} s")
    if workspace is not None:
        outside = np.flatnonzero(~_inside(flange_of(robot)(q), np.asarray(workspace).reshape(3, 2)))
        if outside.size:
            problems.append(f"the flange leaves the workspace box at t = {t[outside[0]]:.4g} s")
    return problems
