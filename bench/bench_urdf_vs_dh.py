#!/usr/bin/env python3
"""The same arm from its URDF and from its DH table: base counts, multiplications/additions of
rnea, gravity and M (dyngen's own count of the C it writes), and generation time (best of 3).

    python bench/bench_urdf_vs_dh.py

Pairs: examples/panda.yaml vs tests/data/urdf/panda.urdf (tip panda_link8), examples/ur5.yaml
vs tests/data/urdf/ur5_robot.urdf. Writes bench/results/urdf_vs_dh.md.
"""
from __future__ import annotations

import time

from common import ROOT, arguments

PAIRS = (("panda", ROOT / "examples/panda.yaml", ROOT / "tests/data/urdf/panda.urdf", "panda_link8"),
         ("ur5", ROOT / "examples/ur5.yaml", ROOT / "tests/data/urdf/ur5_robot.urdf", None))
FUNCTIONS = ("rnea", "gravity", "mass_matrix")


def measure(load):
    from dyngen.generate import build

    best, result = None, None
    for _ in range(3):
        start = time.perf_counter()
        robot = load()
        bases, emitted = build(robot)
        seconds = time.perf_counter() - start
        best = seconds if best is None else min(best, seconds)
        result = (robot, bases, emitted)
    robot, bases, emitted = result
    ops = {f.name[len(robot.name) + 1:]: f.ops for f in emitted.functions}
    return {"counts": "/".join(str(bases[k].rank) for k in ("gravity", "inertia", "full")), "seconds": best,
            **{name: ops[name] for name in FUNCTIONS}}


def main():
    arguments(__doc__, whole=True).parse_args()
    from dyngen.description import load_description

    lines = ["| arm | input | counts g/inertia/full | " + " | ".join(f"{f} mul/add" for f in FUNCTIONS)
             + " | generation [s] |", "|---|---|---|" + "---|" * len(FUNCTIONS) + "---|"]
    for name, yaml, urdf, tip in PAIRS:
        for label, load in (("DH (YAML)", lambda: load_description(yaml)),
                            ("URDF", lambda: load_description(urdf, **({"tip_link": tip} if tip else {})))):
            row = measure(load)
            lines.append(f"| {name} | {label} | {row['counts']} | "
                         + " | ".join(f"{row[f].mul}/{row[f].add}" for f in FUNCTIONS) + f" | {row['seconds']:.2f} |")
            print(lines[-1], flush=True)
    out = ROOT / "bench/results/urdf_vs_dh.md"
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
