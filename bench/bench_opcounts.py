#!/usr/bin/env python3
"""Operation counts of every generated function, per arm: multiplications, additions,
divisions and sin/cos, as dyngen's emitter counts them in the C it writes (manifest.json;
the rule: generator/dyngen/emission/opcount.py). Each arm is generated afresh into a
temporary folder, so the table describes the current generator, not a committed folder.

    python bench/bench_opcounts.py [--arms lwr panda ...]

Writes bench/results/opcounts.md and opcounts.json.
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
from common import arguments, log  # noqa: E402  (bench/ is sys.path[0])


def arm_counts(yaml_path: Path, tmp: Path) -> dict:
    """{"name", "dof", "functions": {short name: ops}} of one freshly generated arm."""
    from dyngen.generate import generate

    manifest = json.loads((generate(yaml_path, tmp).folder / "manifest.json").read_text())
    prefix = manifest["robot"] + "_"
    return {"name": manifest["robot"], "dof": manifest["dof"],
            "functions": {f["name"][len(prefix):]: f["ops"] for f in manifest["functions"]}}


def cell(ops: dict | None) -> str:
    if ops is None:  # the friction routine: a loop with branches, no straight-line count
        return "loop, not counted"
    text = f"{ops['mul']} / {ops['add']} / {ops['sin_cos']}"
    return text + (f" (+{ops['div']} div)" if ops["div"] else "")


def table(arms: list) -> str:
    functions = []
    for a in arms:
        functions += [f for f in a["functions"] if f not in functions]
    lines = ["| function | " + " | ".join(f"{a['name']} ({a['dof']})" for a in arms) + " |",
             "|---|" + "---:|" * len(arms)]
    for f in functions:
        lines.append(f"| `<arm>_{f}` | " + " | ".join(cell(a["functions"][f]) if f in a["functions"] else "-"
                                                       for a in arms) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    from common import arm_yaml, example_arms

    ap = arguments(__doc__)
    ap.add_argument("--arms", nargs="+", help="example names or YAML paths; default: all examples")
    ap.add_argument("--output", default=str(BENCH / "results" / "opcounts.md"),
                    help="markdown results (default bench/results/opcounts.md; the .json next to it); '' to skip")
    args = ap.parse_args(argv)
    names = args.arms or example_arms()
    with tempfile.TemporaryDirectory(prefix="dyngen-bench-ops-") as tmp:
        arms = []
        for name in names:
            log(f"generating {name} ...")
            arms.append(arm_counts(arm_yaml(name), Path(tmp)))
    text = ("# Operation counts of the generated functions\n\n"
            "Written by `python bench/bench_opcounts.py`. Each cell: multiplications / additions (subtractions "
            "included) / sin and cos calls, counted in the emitted C (divisions noted where there are any); "
            "the column head gives the number of joints. Straight-line code is counted as printed; "
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
