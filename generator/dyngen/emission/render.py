"""Render one robot's folder: header, C sources, CMake file, manifest, coefficient list."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import jinja2

from .. import __version__
from ..derivation.models import base_regressor_outputs, coefficient_jacobian_model, coefficient_model
from ..parameters import PER_LINK, dynamic_name, standard_name
from ..reduction.identifiability import classify
from .c_code import render_function
from .coefficients import dynamic_names_text, grouped_text
from .eigen import eigen_interface
from .inertia_regressor import render_inertia_regressor
from .selftest import N_STATES, TOLERANCE, c_numbers, selftest_data

TEMPLATES = Path(__file__).resolve().parents[1] / "templates"  # a link to the top-level templates/, shipped in the wheel
FRICTION_PER_JOINT = 5  # Fc, Fv, Fs, vs, eps (templates/friction.c.j2)
KIND_LABELS = {"gravity": "gravity vector g(q) = Y_g(q) pi_gravity",
               "inertia": "stacked inertia matrix m~(q) = Y_m(q) pi_inertia",
               "full": "inverse dynamics tau = Y(q, qd, qdd) pi_full"}


@dataclass
class Emitted:
    files: dict  # file name -> text
    functions: list  # CFunction
    manifest: dict


def environment() -> jinja2.Environment:
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(TEMPLATES)), trim_blocks=True,
                             lstrip_blocks=True, keep_trailing_newline=True, undefined=jinja2.StrictUndefined)
    env.filters["c_numbers"] = c_numbers
    return env


def emit(robot, derivation, regressors: dict, bases: dict, models: dict) -> Emitted:
    """regressors: "gravity" and "full" -> full regressor Model; bases: kind -> BaseSet; models: rnea,
    gravity, mass_matrix and unit_accelerations (the factors of the inertia regressor)."""
    P, n = robot.name, robot.dof
    joint_models = robot.joint_models
    n_stacked = n * (n + 1) // 2
    std_names = [standard_name(i + 1, k) for i in range(n) for k in range(PER_LINK)]
    dyn_text = dynamic_names_text(n)

    def fn(name, model, outputs, out, doc):
        return render_function(P, joint_models, name, model, outputs, out, doc)

    parameters = [fn("standard_from_dynamic", (m := derivation.standard_from_dynamic()), m.outputs,
                     ("s", (PER_LINK * n,), "standard parameters"), "Standard parameters s from dynamic parameters p.")]
    regressor_fns = []
    kinds = []
    out_rows = {"gravity": n, "full": n}
    for kind in ("gravity", "inertia", "full"):
        base = bases[kind]
        cm = coefficient_model(derivation, base, kind)
        parameters.append(fn(f"pi_{kind}", cm, cm.outputs, ("pi", (base.rank,), f"pi_{kind}"),
                             f"Base coefficients pi_{kind}(p) of the {KIND_LABELS[kind]}."))
        jm = coefficient_jacobian_model(derivation, base, kind)
        parameters.append(fn(f"pi_{kind}_jacobian", jm, jm.outputs, ("J", (base.rank, PER_LINK * n), "row-major"),
                             f"Jacobian d pi_{kind} / d p (for gradient-based extraction)."))
        doc = f"Base regressor of the {KIND_LABELS[kind]}."
        if kind == "inertia":  # factored: O(n^2) code for its O(n^3) entries
            regressor_fns.append(render_inertia_regressor(P, joint_models, models["unit_accelerations"], base, doc))
        else:
            name = {"gravity": "regressor_gravity", "full": "regressor"}[kind]
            regressor_fns.append(fn(name, regressors[kind], base_regressor_outputs(regressors[kind], base),
                                    ("Y", (out_rows[kind], base.rank), "row-major"), doc))
        standard, dynamic = classify(base, n)
        coefficients = []
        for k, row in enumerate(base.K):
            coefficients.append({"index": k, "standard": grouped_text(row, std_names),
                                 "dynamic": grouped_text(row, [dyn_text[s] for s in std_names])})
        kinds.append({"name": kind, "rank": base.rank, "label": KIND_LABELS[kind], "coefficients": coefficients,
                      "pivots": [std_names[j] for j in base.pivots], "standard": standard, "dynamic": dynamic})
    dynamics = [
        fn("rnea", models["rnea"], models["rnea"].outputs, ("tau", (n,), "joint torques/forces"),
           "Inverse dynamics tau = M(q) qdd + c(q, qd) + g(q), recursive Newton-Euler."),
        fn("gravity", models["gravity"], models["gravity"].outputs, ("g", (n,), "gravity torques"),
           "Gravity vector g(q)."),
        fn("mass_matrix", models["mass_matrix"], models["mass_matrix"].outputs, ("M", (n, n), "row-major, symmetric"),
           "Inertia matrix M(q)."),
    ]
    functions = parameters + regressor_fns + dynamics
    env = environment()
    gravity_symbols = [s.name for s in robot.gravity_symbols]
    common = dict(robot=robot, P=P, M=P.upper(), version=__version__, source=robot.source, kinds=kinds,
                  n_stacked=n_stacked, gravity_symbols=gravity_symbols,
                  joint_types="".join("R" if j.revolute else "P" for j in joint_models),
                  gravity_text=", ".join(_gravity_text(g) for g in robot.gravity), FRICTION_PER_JOINT=FRICTION_PER_JOINT)
    sources = {f"{P}_parameters.c": ("parameters and base coefficients", parameters),
               f"{P}_regressors.c": ("base regressors", regressor_fns),
               f"{P}_dynamics.c": ("inverse dynamics, gravity and inertia matrix", dynamics)}
    files = {f"{P}.h": env.get_template("header.h.j2").render(functions=functions, **common)}
    for filename, (summary, fns) in sources.items():
        files[filename] = env.get_template("source.c.j2").render(filename=filename, summary=summary,
                                                                  functions=fns, **common)
    files[f"{P}_friction.c"] = env.get_template("friction.c.j2").render(**common)
    files[f"{P}_extract.cpp"] = env.get_template("extract.cpp.j2").render(**common)
    check = selftest_data(robot, derivation, models)
    files[f"{P}_selftest.c"] = env.get_template("selftest.c.j2").render(
        data=check, call=_selftest_calls(P, functions), n_states=N_STATES, tolerance=TOLERANCE, **common)
    files[f"{P}.hpp"] = env.get_template("eigen.hpp.j2").render(
        eigen=eigen_interface(P, functions), **common)
    library = sorted([*sources, f"{P}_friction.c"])
    files["CMakeLists.txt"] = env.get_template("CMakeLists.txt.j2").render(sources=library, **common)
    files["coefficients.md"] = env.get_template("coefficients.md.j2").render(**common)
    manifest = _manifest(robot, functions, kinds, std_names, n_stacked)
    manifest["functions"].append(_friction_manifest(P, n))
    manifest["files"] = {"library": library, "header": f"{P}.h", "eigen_header": f"{P}.hpp",
                         "selftest": f"{P}_selftest.c", "cmake": "CMakeLists.txt"}
    manifest["selftest"] = check.as_dict() | {"tolerance": TOLERANCE}
    files["manifest.json"] = json.dumps(manifest, indent=1) + "\n"
    return Emitted(files, functions, manifest)


def _selftest_calls(P: str, functions) -> dict:
    """Short name -> the C call the self-test makes; its arrays are named like the arguments."""
    outputs = {"standard_from_dynamic": "s", "rnea": "tau", "gravity": "g", "mass_matrix": "M",
               "regressor_gravity": "Y_gravity", "regressor_inertia": "Y_inertia", "regressor": "Y_full",
               "pi_gravity": "pi_gravity", "pi_inertia": "pi_inertia", "pi_full": "pi_full"}
    calls = {}
    for f in functions:
        short = f.name[len(P) + 1:]
        if short in outputs:
            calls[short] = f"{f.name}({', '.join([name for name, _, _ in f.inputs] + [outputs[short]])})"
    return calls


def _friction_manifest(P: str, n: int) -> dict:
    """The optional friction routine (not a straight-line program: a loop over joints)."""
    return {"name": f"{P}_friction", "doc": "Joint friction (Coulomb, viscous, Stribeck), templates/friction.c.j2.",
            "inputs": [{"name": "qd", "length": n, "meaning": "joint velocities"},
                       {"name": "f", "length": FRICTION_PER_JOINT * n,
                        "meaning": "per joint Fc, Fv, Fs, vs, eps"}],
            "output": {"name": "tau", "shape": [n], "meaning": "friction torques"},
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
