"""Render one robot's folder: header, C sources, CMake file, manifest, coefficient list."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import jinja2

from .. import __version__, catalogue
from ..catalogue import FRICTION_PER_JOINT, KIND_LABELS, KINDS
from ..derivation.models import base_regressor_outputs, coefficient_jacobian_model, coefficient_model
from ..parameters import PER_LINK, dynamic_name, standard_name
from ..reduction.identifiability import classify
from ..terms.friction import c_terms
from .c_code import CFunction, render_function
from .coefficients import dynamic_names_text, grouped_text
from .eigen import eigen_interface
from .inertia_regressor import render_inertia_regressor
from .outputs import render_outputs
from .selftest import N_STATES, TOLERANCE, c_numbers, selftest_checks, selftest_data

TEMPLATES = Path(__file__).resolve().parents[1] / "templates"  # package data, shipped in the wheel


@dataclass
class Emitted:
    files: dict  # file name -> text
    functions: list  # CFunction
    manifest: dict


def _friction_c_names(P: str):
    """The C names the friction terms' expressions use (defined in templates/friction.c.j2)."""
    from types import SimpleNamespace

    M = P.upper()
    return SimpleNamespace(sgn=f"{M}_SGN", exp=f"{M}_EXP", abs=f"{M}_ABS", zero=f"{M}_K(0)")


def environment() -> jinja2.Environment:
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(TEMPLATES)), trim_blocks=True,
                             lstrip_blocks=True, keep_trailing_newline=True, undefined=jinja2.StrictUndefined)
    env.filters["c_numbers"] = c_numbers
    return env


def emit(robot, derivation, regressors: dict, bases: dict, models: dict) -> Emitted:
    """regressors: "gravity" and "full" -> full regressor Model; bases: kind -> BaseSet; models: rnea,
    gravity, mass_matrix and unit_accelerations (the factors of the inertia regressor)."""
    P, n = robot.name, robot.dof
    n_stacked = n * (n + 1) // 2
    std_names = [standard_name(i + 1, k) for i in range(n) for k in range(PER_LINK)]
    dyn_text = dynamic_names_text(n)
    dims = catalogue.dimensions(n, {kind: bases[kind].rank for kind in KINDS}, len(robot.gravity_symbols))
    programs = _programs(derivation, regressors, bases, models)
    functions = [_c_function(robot, f, programs, models, bases, dims) for f in _straight_line()]
    kinds = []
    for kind in KINDS:
        base = bases[kind]
        standard, dynamic = classify(base, n)
        coefficients = []
        for k, row in enumerate(base.K):
            coefficients.append({"index": k, "standard": grouped_text(row, std_names),
                                 "dynamic": grouped_text(row, [dyn_text[s] for s in std_names])})
        kinds.append({"name": kind, "rank": base.rank, "label": KIND_LABELS[kind], "coefficients": coefficients,
                      "pivots": [std_names[j] for j in base.pivots], "standard": standard, "dynamic": dynamic})
    env = environment()
    gravity_symbols = [s.name for s in robot.gravity_symbols]
    common = dict(robot=robot, P=P, M=P.upper(), version=__version__, source=robot.source, kinds=kinds,
                  n_stacked=n_stacked, gravity_symbols=gravity_symbols,
                  joint_types="".join("R" if j.revolute else "P" for j in robot.joint_models),
                  gravity_text=", ".join(_gravity_text(g) for g in robot.gravity), FRICTION_PER_JOINT=FRICTION_PER_JOINT)
    sources = {f"{P}_{source}.c": (summary, [c for f, c in zip(_straight_line(), functions) if f.source == source])
               for source, summary in catalogue.SOURCES.items()}
    files = {f"{P}.h": env.get_template("header.h.j2").render(functions=functions, **common)}
    for filename, (summary, fns) in sources.items():
        files[filename] = env.get_template("source.c.j2").render(filename=filename, summary=summary,
                                                                  functions=fns, **common)
    files[f"{P}_friction.c"] = env.get_template("friction.c.j2").render(
        friction_terms=c_terms(_friction_c_names(P)), **common)
    files[f"{P}_kinds.h"] = env.get_template("kinds.h.j2").render(
        standard_from_dynamic=catalogue.STANDARD_FROM_DYNAMIC.name,
        kinds=[{"name": kind, "pi": catalogue.COEFFICIENTS[kind].name, "jacobian": catalogue.JACOBIANS[kind].name}
               for kind in KINDS], **{k: v for k, v in common.items() if k != "kinds"})
    check = selftest_data(robot, programs)
    files[f"{P}_selftest.c"] = env.get_template("selftest.c.j2").render(
        data=check, checks=selftest_checks(P, dims, bool(gravity_symbols)), n_states=N_STATES,
        tolerance=TOLERANCE, **common)
    eigen = eigen_interface(P, dims, {c.name: c.doc for c in functions})
    files[f"{P}.hpp"] = env.get_template("eigen.hpp.j2").render(eigen=eigen, **common)
    library = sorted([*sources, f"{P}_friction.c"])
    files["CMakeLists.txt"] = env.get_template("CMakeLists.txt.j2").render(sources=library, **common)
    files["coefficients.md"] = env.get_template("coefficients.md.j2").render(**common)
    manifest = _manifest(robot, functions, kinds, std_names, n_stacked)
    manifest["functions"].append(_template_function_manifest(P, catalogue.FRICTION, dims))
    manifest["files"] = {"library": library, "header": f"{P}.h", "eigen_header": f"{P}.hpp",
                         "selftest": f"{P}_selftest.c", "cmake": "CMakeLists.txt",
                         "extractor_kinds": f"{P}_kinds.h"}
    manifest["selftest"] = check.as_dict() | {"tolerance": TOLERANCE}
    if robot.convention == "urdf":  # what the URDF reader changed: every snapped constant, every lumped link
        manifest["urdf"] = {"links": list(robot.links), "notes": list(robot.notes),
                            "snaps": [{"joint": x.joint, "field": x.field, "from": x.before, "to": x.after,
                                       "gravity_torque_change_max": effect}
                                      for x, effect in zip(robot.snaps, robot.snap_effects or [None] * len(robot.snaps))]}
    files["manifest.json"] = json.dumps(manifest, indent=1) + "\n"
    return Emitted(files, functions, manifest)


def _straight_line() -> list:
    return [f for f in catalogue.FUNCTIONS if f.model != "template"]


def _programs(derivation, regressors: dict, bases: dict, models: dict) -> dict:
    """Catalogue name -> (derivation Model, its flat outputs) of every straight-line function
    but the factored inertia regressor."""
    out = {}
    for f in _straight_line():
        if f.model == "standard_from_dynamic":
            model = derivation.standard_from_dynamic()
        elif f.model == "coefficients":
            model = coefficient_model(derivation, bases[f.kind], f.kind)
        elif f.model == "coefficient_jacobian":
            model = coefficient_jacobian_model(derivation, bases[f.kind], f.kind)
        elif f.kind and f.model not in ("coefficients", "coefficient_jacobian", "unit_accelerations"):
            full = regressors[f.kind] if f.model == "regressor" else models[f.model]  # over all 10N columns
            out[f.name] = (full, base_regressor_outputs(full, bases[f.kind]))
            continue
        elif f.model == "unit_accelerations":
            continue
        else:
            model = models[f.model]
        out[f.name] = (model, model.outputs)
    return out


def _c_function(robot, f, programs: dict, models: dict, bases: dict, dims: dict) -> CFunction:
    P = robot.name
    if f.model == "unit_accelerations":  # factored: O(n^2) code for its O(n^3) entries
        c = render_inertia_regressor(P, robot.joint_models, models["unit_accelerations"], bases[f.kind], f.doc)
    elif f.more:  # one program, several output arrays
        model, _ = programs[f.name]
        outs = [(o.name, tuple(dims[d] for d in o.shape), o.meaning) for o in f.outputs]
        c = render_outputs(P, robot.joint_models, f.name, model, outs, f.doc)
    else:
        model, outputs = programs[f.name]
        output = (f.output.name, tuple(dims[d] for d in f.output.shape), f.output.meaning)
        c = render_function(P, robot.joint_models, f.name, model, outputs, output, f.doc)
    expected = f.arguments(bool(robot.gravity_symbols))
    assert c.name == f"{P}_{f.name}" and tuple(name for name, _, _ in c.inputs) == expected, (c.name, c.inputs)
    for written, o in zip(c.outputs, f.outputs, strict=True):
        assert written[0] == o.name and tuple(written[1]) == tuple(dims[d] for d in o.shape), written
    return c


def _template_function_manifest(P: str, f, dims: dict) -> dict:
    """A function written by its own template (not a straight-line program: a loop over joints)."""
    return {"name": f"{P}_{f.name}", "doc": f.doc,
            "inputs": [{"name": a, "length": math.prod(dims[d] for d in catalogue.ARGUMENTS[a].shape),
                        "meaning": catalogue.ARGUMENTS[a].meaning} for a in f.inputs],
            "output": {"name": f.output.name, "shape": [dims[d] for d in f.output.shape], "meaning": f.output.meaning},
            "outputs": [{"name": f.output.name, "shape": [dims[d] for d in f.output.shape], "meaning": f.output.meaning}],
            "ops": None}


def _gravity_text(g) -> str:
    return str(float(g)) if g.is_number else str(g)


def _manifest(robot, functions, kinds, std_names, n_stacked) -> dict:
    n = robot.dof
    return {
        "generator": f"dyngen {__version__}",
        "robot": robot.name,
        "source": robot.source,
        "dof": n,
        "convention": robot.convention,
        "joint_types": [j.type for j in robot.joints],
        "gravity": [_gravity_text(g) for g in robot.gravity],
        "gravity_symbols": [s.name for s in robot.gravity_symbols],
        "parameters": {
            "dynamic": [dynamic_name(i + 1, k) for i in range(n) for k in range(PER_LINK)],
            "standard": std_names,
        },
        "stacked_inertia_order": [f"M{j + 1}{k + 1}" for j in range(n) for k in range(j, n)],
        "functions": [{
            "name": f.name, "doc": f.doc,
            "inputs": [{"name": a, "length": length, "meaning": m} for a, length, m in f.inputs],
            "output": {"name": f.output[0], "shape": list(f.output[1]), "meaning": f.output[2]},
            "outputs": [{"name": name, "shape": list(shape), "meaning": meaning} for name, shape, meaning in f.outputs],
            "ops": {"mul": f.ops.mul, "add": f.ops.add, "div": f.ops.div, "sin_cos": f.ops.trig},
        } for f in functions],
        "coefficients": {k["name"]: {
            "rank": k["rank"],
            "base_columns": k["pivots"],
            "expressions": [{"standard": c["standard"], "dynamic": c["dynamic"]} for c in k["coefficients"]],
            "identifiable_alone": list(k["standard"].alone),
            "grouped": list(k["standard"].grouped),
            "absent": list(k["standard"].absent),
            "dynamic_alone": list(k["dynamic"].alone),
            "dynamic_absent": list(k["dynamic"].absent),
        } for k in kinds},
    }
