#!/usr/bin/env python3
"""Operation counts of every generated function, per arm: multiplications, additions,
divisions and sin/cos, as dyngen's emitter counts them in the C it writes (manifest.json;
the rule: generator/dyngen/emission/opcount.py). Each arm is generated afresh into a
temporary folder, so the table describes the current generator, not a committed folder.
Beside each count: the float32 build's error against the double build (<ROBOT>_USE_FLOAT,
dyngen.runtime), the worst normwise relative error max_k |f_k - d_k| / max_k |d_k| over
--states random states (float-representable inputs, so the difference is the float
computation alone; 10 random consistent parameter sets, one per tenth of the states).

    python bench/bench_opcounts.py [--arms lwr panda ...] [--states 100000]

Writes bench/results/opcounts.md and opcounts.json.
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

from common import BENCH, arguments, log, on_path


def arm_counts(yaml_path: Path, tmp: Path, states: int) -> dict:
    """{"name", "dof", "functions": {short name: ops}, "float_error": {short name: error}} of one
    freshly generated arm."""
    from dyngen.generate import generate

    folder = generate(yaml_path, tmp).folder
    manifest = json.loads((folder / "manifest.json").read_text())
    prefix = manifest["robot"] + "_"
    return {"name": manifest["robot"], "dof": manifest["dof"],
            "functions": {f["name"][len(prefix):]: f["ops"] for f in manifest["functions"]},
            "float_error": float_errors(folder, manifest, states, tmp) if states else {}}


PARAMETER_SETS = 10
CHUNK = 2000  # states per batch call (the inertia regressor's output is large)


def float_errors(folder: Path, manifest: dict, states: int, tmp: Path) -> dict:
    """Worst normwise relative error of the float build against the double build, per function."""
    import numpy as np

    on_path()
    from oracles.random_params import random_parameters

    from dyngen.runtime import load
    from dyngen.terms.friction import FRICTION_FIELDS

    double = load(folder, cache_dir=tmp / "double")
    single = load(folder, cache_dir=tmp / "float", real="float")
    n, prefix = manifest["dof"], manifest["robot"] + "_"
    revolute = np.array([t == "revolute" for t in manifest["joint_types"]])
    n_gravity = len(manifest["gravity_symbols"])
    rng = np.random.default_rng(7)
    worst: dict = {}

    def f32(a):
        return np.asarray(a, dtype=np.float32).astype(np.float64)

    def flat(out, rows):  # a function with several outputs (control): each state's outputs side by side
        outs = out if isinstance(out, tuple) else (out,)
        return np.concatenate([np.asarray(o, dtype=np.float64).reshape(rows, -1) for o in outs], axis=1)

    def compare(name, inputs):
        rows = len(inputs[0]) if inputs[0].ndim == 2 else 1
        d = flat(double.batch(name, *inputs), rows)
        f = flat(single.batch(name, *inputs), rows)
        scale = np.max(np.abs(d), axis=1)
        err = np.max(np.abs(f - d), axis=1) / np.where(scale > 0, scale, 1.0)
        worst[name] = max(worst.get(name, 0.0), float(err.max()))

    per_set = max(1, states // PARAMETER_SETS)
    for _ in range(PARAMETER_SETS):
        p = f32(random_parameters(n, seed=rng))
        values = {"p": p, "s": f32(double("standard_from_dynamic", p)), "pi_full": f32(double("pi_full", p))}
        for done in range(0, per_set, CHUNK):
            T = min(CHUNK, per_set - done)
            q = np.where(revolute, rng.uniform(-np.pi, np.pi, (T, n)), rng.uniform(0.2, 1.0, (T, n)))
            values |= {"q": f32(q), "qd": f32(rng.uniform(-2, 2, (T, n))), "qdd": f32(rng.uniform(-5, 5, (T, n))),
                       "qr_d": f32(rng.uniform(-2, 2, (T, n))), "qr_dd": f32(rng.uniform(-5, 5, (T, n))),
                       "tau": f32(rng.uniform(-20, 20, (T, n))),
                       "gravity": f32(9.81 * rng.standard_normal((T, n_gravity))),
                       # friction: per joint its terms' fields (terms/friction.py): values and velocity scales
                       "f": f32(np.column_stack([rng.uniform(0, 2, T * n) if field.kind == "value" else
                                                 rng.uniform(1e-3, 0.5, T * n)
                                                 for field in FRICTION_FIELDS]).reshape(T, -1))}
            for fn in manifest["functions"]:
                names = [i["name"] for i in fn["inputs"]]
                if set(names) <= {"p"} and done:
                    continue  # a function of p alone: once per parameter set
                compare(fn["name"][len(prefix):], [values[x] for x in names])
    return worst


def cell(ops: dict | None, error: float | None = None) -> str:
    suffix = f"; f32 {error:.0e}" if error is not None else ""
    if ops is None:  # the friction routine: a loop with branches, no straight-line count
        return "loop, not counted" + suffix
    text = f"{ops['mul']} / {ops['add']} / {ops['sin_cos']}"
    return text + (f" (+{ops['div']} div)" if ops["div"] else "") + suffix


def table(arms: list) -> str:
    functions = []
    for a in arms:
        functions += [f for f in a["functions"] if f not in functions]
    lines = ["| function | " + " | ".join(f"{a['name']} ({a['dof']})" for a in arms) + " |",
             "|---|" + "---:|" * len(arms)]
    for f in functions:
        lines.append(f"| `<arm>_{f}` | " + " | ".join(cell(a["functions"][f], a["float_error"].get(f))
                                                       if f in a["functions"] else "-" for a in arms) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    from common import arm_yaml, example_arms

    ap = arguments(__doc__)
    ap.add_argument("--arms", nargs="+", help="example names or YAML paths; default: all examples")
    ap.add_argument("--output", default=str(BENCH / "results" / "opcounts.md"),
                    help="markdown results (default bench/results/opcounts.md; the .json next to it); '' to skip")
    ap.add_argument("--states", type=int, default=100_000,
                    help="random states for the float32 error (default 100000; 0: no float build)")
    args = ap.parse_args(argv)
    names = args.arms or example_arms()
    with tempfile.TemporaryDirectory(prefix="dyngen-bench-ops-") as tmp:
        arms = []
        for name in names:
            log(f"generating {name} ...")
            arms.append(arm_counts(arm_yaml(name), Path(tmp) / Path(name).stem, args.states))  # a YAML path: its stem
    text = ("# Operation counts of the generated functions\n\n"
            "Written by `python bench/bench_opcounts.py`. Each cell: multiplications / additions (subtractions "
            "included) / sin and cos calls, counted in the emitted C (divisions noted where there are any); "
            "the column head gives the number of joints; `f32`: the float32 build's worst normwise relative "
            f"error against the double build over {args.states} random states (max_k |f_k - d_k| / max_k |d_k|; "
            "for `inverse_dynamics` the base coefficients' own size matters: a coefficient like m + MY/0.0203 "
            "(PUMA 560) makes the sum Y pi cancel, tests/test_float_build.py). The sin/cos column counts "
            "calls: one per angle whose sine and cosine are both needed (a polynomial sincos in the emitted "
            "C, emission/c_code.py). Straight-line code is counted as printed; "
            "`<arm>_regressor_inertia` (Y_m) is straight-line link motions plus a loop over its base columns, "
            "counted as the motions' operations plus each column's loop trips times its loop body "
            "(generator/dyngen/emission/inertia_regressor.py; index arithmetic not counted).\n\n"
            + table(arms) + "\n")
    print(text)
    if args.output:
        out = Path(args.output)
        out.write_text(text)
        out.with_suffix(".json").write_text(json.dumps(arms, indent=1) + "\n")
        log(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
