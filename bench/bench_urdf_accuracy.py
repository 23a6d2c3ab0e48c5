#!/usr/bin/env python3
"""dyngen's C from each example-robot-data URDF (snapped) against Pinocchio reading the ORIGINAL
file: worst relative error of rnea, gravity and M over 1000 random states, and the counts beside
the numerical rank of Pinocchio's regressor.

    python bench/bench_urdf_accuracy.py        (writes bench/results/urdf_accuracy.md)
"""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin
from common import arguments, on_path

ROOT = on_path()
from cbuild import compile_folder  # noqa: E402
from test_urdf import ARMS, DATA, configuration, numerical_rank, pinocchio_chain, rel_err  # noqa: E402

from dyngen.atomic import write_folder  # noqa: E402
from dyngen.description.urdf import load_urdf  # noqa: E402
from dyngen.generate import build  # noqa: E402

STATES = 1000


def main():
    arguments(__doc__, whole=True).parse_args()
    lines = ["| arm | snaps | counts g/inertia/full | Pinocchio rank g/full | rnea | gravity | M |", "|---|---|---|---|---|---|---|"]
    for name, (file, tip) in sorted(ARMS.items()):
        robot = load_urdf(DATA / file, tip_link=tip)
        bases, emitted = build(robot)
        with tempfile.TemporaryDirectory() as tmp:
            write_folder(Path(tmp) / robot.name, emitted.files)
            c = compile_folder(Path(tmp) / robot.name, Path(tmp) / "build")
            model, data = pinocchio_chain(DATA / file, robot.links)
            ranks = (numerical_rank(model, data, "gravity", np.random.default_rng(1)),
                     numerical_rank(model, data, "full", np.random.default_rng(2)))
            s = c("standard_from_dynamic", np.concatenate([v.as_tuple() for v in robot.nominal]))
            rng = np.random.default_rng(0)
            worst = [0.0, 0.0, 0.0]
            for _ in range(STATES):
                n = robot.dof
                q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)
                x = configuration(model, q)
                M = pin.crba(model, data, x).copy()
                for k, (got, want) in enumerate(((c("rnea", q, qd, qdd, s), pin.rnea(model, data, x, qd, qdd)),
                                                 (c("gravity", q, s), pin.computeGeneralizedGravity(model, data, x)),
                                                 (c("mass_matrix", q, s), np.triu(M) + np.triu(M, 1).T))):
                    worst[k] = max(worst[k], rel_err(got, want))
        counts = "/".join(str(bases[k].rank) for k in ("gravity", "inertia", "full"))
        lines.append(f"| {name} | {len(robot.snaps)} | {counts} | {ranks[0]}/{ranks[1]} | "
                     + " | ".join(f"{w:.1e}" for w in worst) + " |")
        print(lines[-1], flush=True)
    (ROOT / "bench/results/urdf_accuracy.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
