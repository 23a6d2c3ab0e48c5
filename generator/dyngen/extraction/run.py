"""The extract step: targets from the YAML, stages as in the paper, the driver, checks."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..parameters import PER_LINK, consistency_margin, dynamic_name
from ..reduction.identifiability import classify
from . import driver
from .problem import Infeasible, Options, Problem, Stage, build_problem
from .targets import Target, target

KINDS = ("gravity", "inertia", "full")


@dataclass
class Extraction:
    p: np.ndarray  # dynamic parameters, 10N
    problem: Problem
    targets: dict  # kind -> Target
    stages: list  # driver.StageResult


def targets_of(robot, bases) -> dict[str, Target]:
    found = {kind: target(robot, bases[kind], kind) for kind in KINDS}
    found = {k: t for k, t in found.items() if t is not None}
    if not found:
        raise InputError(robot.source, "identified", "missing: extraction needs identified coefficients")
    return found


def plan(robot, bases, targets: dict, problem: Problem, options: Options) -> list[Stage]:
    n = PER_LINK * robot.dof
    everything = np.ones(n, dtype=bool)
    if options.procedure == "joint" or "gravity" not in targets:
        return [Stage("joint", list(targets.values()), everything, problem.reference.copy())]
    stages = [Stage("gravity", [targets["gravity"]], everything, problem.reference.copy())]
    rest = [targets[k] for k in ("inertia", "full") if k in targets]
    if rest:  # the paper's second stage: the gravity stage's parameters p'_g stay fixed
        _, dynamic = classify(bases["gravity"], robot.dof)
        in_gravity = set(dynamic.alone) | set(dynamic.grouped)
        free = np.array([dynamic_name(j // PER_LINK + 1, j % PER_LINK) not in in_gravity for j in range(n)])
        stages.append(Stage("inertia", rest, free, problem.reference.copy()))
        stages[0].next_blocks = rest
    return stages


def extract(robot, bases, folder: Path, options: Options | None = None, on_progress=None) -> Extraction:
    options = options or Options()
    targets = targets_of(robot, bases)
    problem = build_problem(robot, options)
    exe = driver.build(folder)
    stages = plan(robot, bases, targets, problem, options)
    value = problem.reference.copy()
    results = []
    for stage in stages:
        stage.value = value
        result = driver.run(exe, problem, stage, options,
                            (lambda d, t, s=stage.name: on_progress(s, d, t)) if on_progress else None)
        results.append(result)
        if result.status != "ok":
            raise Infeasible(f"{robot.source}: stage {stage.name}: no restart satisfied all constraints; "
                             + name_violations(problem, result.p, options))
        value = result.p
    return Extraction(value, problem, targets, results)


def name_violations(problem: Problem, p, options: Options) -> str:
    """What the least violating point breaks: bounds, consistency, total mass, identities."""
    if p is None:
        return "no point to inspect"
    broken = []
    for j in np.flatnonzero((p < problem.lower - options.tolerance) | (p > problem.upper + options.tolerance)):
        broken.append(f"bounds of {dynamic_name(j // PER_LINK + 1, j % PER_LINK)}")
    for link, row in enumerate(np.asarray(p).reshape(-1, PER_LINK)):
        if consistency_margin(row) < options.margin - options.tolerance:
            broken.append(f"consistency of link {link + 1}")
    if problem.total_mass is not None:
        total = p[::PER_LINK].sum()
        lo, hi = problem.total_mass
        if not lo - options.tolerance <= total <= hi + options.tolerance:
            broken.append(f"total mass {total:.4g} outside [{lo:g}, {hi:g}]")
    for k, terms in enumerate(problem.equalities):
        h = sum(c * np.prod([p[i] for i in idx]) for c, idx in terms)
        if abs(h) > options.tolerance:
            broken.append(f"identity {k + 1} (off by {h:.3g})")
    return "conflicting constraints: " + (", ".join(broken) or "none found at the closest point")
