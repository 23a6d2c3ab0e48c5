"""The generate step: YAML -> derivation -> reduction -> emitted folder."""

from __future__ import annotations

import gc
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from .atomic import write_folder
from .catalogue import KINDS
from .derivation.control import control_model
from .derivation.kinematics_functions import KinematicsModels
from .derivation.controller import controller_models
from .derivation.models import Derivation
from .description import Robot, load_robot
from .emission.opcount import count_all
from .emission.render import Emitted, emit
from .emission.selftest import fixed_parameters
from .progress import Progress
from .errors import InputError
from .reduction.base import BaseSet, reduce_model
from .reduction.exact import NotInField


@dataclass
class Generated:
    robot: Robot
    bases: dict  # kind -> BaseSet
    emitted: Emitted
    folder: Path


@contextmanager
def _fewer_collections(first_generation: int = 100_000):
    """SymPy allocates millions of small objects, nearly all freed by reference counting.
    Python's cycle collector still runs every 700 allocations and, now and then, rescans
    the whole (growing) heap, which made generation time grow faster than its output: at 18
    joints 10% of it. A larger first threshold keeps the collector, with rarer runs."""
    thresholds = gc.get_threshold()
    gc.set_threshold(first_generation, *thresholds[1:])
    try:
        yield
    finally:
        gc.set_threshold(*thresholds)


def build(robot: Robot, progress: Progress | None = None) -> tuple[dict, Emitted]:
    """Derive, reduce and render in memory (nothing written)."""
    with _fewer_collections():
        return _build(robot, progress or Progress(quiet=True))


def _build(robot: Robot, progress: Progress) -> tuple[dict, Emitted]:
    derivation = Derivation(robot)
    with progress.step("derive regressors (symbolic Newton-Euler)"):
        # The inertia matrix's base set comes from the full regressor without gravity (O(n^2) code)
        # rather than from Y_m (O(n^3)): reduction/base.py says why they agree.
        regressors = {kind: derivation.regressor(kind) for kind in ("gravity", "full")}
        reduced = {**regressors, "inertia": derivation.regressor("full_without_gravity")}
    with progress.step("reduce to base coefficients (exact rank)"):
        try:
            bases: dict[str, BaseSet] = {kind: reduce_model(reduced[kind], kind) for kind in KINDS}
        except NotInField as err:  # non-exact angles whose products outgrow the largest prime
            raise InputError(robot.source, "", f"the exact regrouping failed ({err}); a URDF's angles "
                             "that are not multiples of pi/12 make it grow: let dyngen snap them (drop --no-snap)") from None
        if bases["gravity"].rank == 0:  # C has no zero-length arrays for pi_gravity and Y_g
            raise InputError(robot.source, "gravity", "no joint of this arm moves against gravity (the gravity "
                             "vector is identically zero, e.g. a horizontal SCARA); dyngen needs at least one "
                             "gravity coefficient: tilt the base slightly or give gravity a symbol")
    with progress.step("derive the dynamics over the base coefficients"):
        # each function over its own kind's coefficients (Derivation.rnea says why that is exact)
        models = {"rnea": derivation.rnea(bases["full"]),
                  "rnea_nominal": derivation.rnea_nominal(bases["full"], fixed_parameters(robot)),
                  "gravity": derivation.gravity(bases["gravity"]),
                  "mass_matrix": derivation.mass_matrix(bases["inertia"]),
                  "inverse_dynamics": derivation.inverse_dynamics(bases["full"]),
                  "unit_accelerations": derivation.unit_accelerations(), **KinematicsModels(robot).all(),
                  "control": control_model(robot, bases),
                  "control_with_jacobian": control_model(robot, bases, with_jacobian=True),
                  **controller_models(derivation, operations, bases)}
    with progress.step("emit C"):
        emitted = emit(robot, derivation, regressors, bases, models)
    return bases, emitted


def operations(model) -> int:
    """Multiplications, additions and divisions of a model's straight-line code."""
    ops = count_all([a.expr for a in model.assignments] + list(model.outputs))
    return ops.mul + ops.add + ops.div


def generate(robot: Robot | str | Path, out_root="generated", progress: Progress | None = None) -> Generated:
    """Generate into out_root/<robot name>/; nothing is written unless everything succeeded.
    out_root None: into the per-user cache (see cached_folder) instead."""
    progress = progress or Progress(quiet=True)
    if not isinstance(robot, Robot):
        robot = load_robot(robot)
    bases, emitted = build(robot, progress)
    if out_root is None:
        return Generated(robot, bases, emitted, cached_folder(robot.name, emitted.files))
    folder = Path(out_root) / robot.name
    write_folder(folder, emitted.files)
    return Generated(robot, bases, emitted, folder)


def cached_folder(name: str, files: dict[str, str]) -> Path:
    """The generated files in the per-user cache, keyed by their content. Commands that need a
    compiled model but no output folder (identify, diagnose, extract before it succeeds) use
    it: nothing is left in the temporary directory or in the user's folders, and a second run
    with the same model reuses the folder and its compiled library (only when it still holds
    exactly these files: dyngen.cache.model_folder)."""
    from . import cache

    return cache.model_folder(name, files)
