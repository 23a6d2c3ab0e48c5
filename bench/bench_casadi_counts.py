#!/usr/bin/env python3
"""Operation counts of the controller and kinematics functions: dyngen's emitted C (mul + add +
div, the manifest's counts) beside CasADi's SX algorithm of the same function (n_instructions of
the casadi.Function bench/casadi_side.py code-generates, parameters as input and baked; it also
counts the input, output and constant instructions, so it is an upper bound of its arithmetic).
No compiler involved: the quick companion of bench_controller.py and bench_kinematics.py, whose
callgrind counts are the speed claim.

    python bench/bench_casadi_counts.py [--arms lwr panda ...] [--output bench/results/casadi_counts.md]
"""
from __future__ import annotations

import json
from pathlib import Path

from common import BENCH, arguments, arm_yaml, example_arms, log, on_path

on_path()
import casadi_side  # noqa: E402
from bench_dynamics import dynamic_parameters  # noqa: E402

CONTROLLER = {"coriolis": "coriolis_matrix", "mass_matrix_dot": "mass_matrix_derivative",
              "slotine_li": "regressor_slotine_li", "fd": "forward_dynamics", "rnea_derivatives": "rnea_derivatives",
              "fd_derivatives": "forward_dynamics_derivatives"}
KINEMATICS = {f: f for f in casadi_side.KINEMATICS_FUNCTIONS}


def arm_rows(name: str) -> list:
    from oracles import kinematics as kin
    from oracles import pinocchio_arm
    from oracles.arm import Arm

    from dyngen.description import load_robot
    from dyngen.generate import build

    yaml_path = arm_yaml(name)
    robot = load_robot(yaml_path)
    manifest = json.loads(build(robot)[1].files["manifest.json"])
    ops = {f["name"][len(robot.name) + 1:]: f["ops"] for f in manifest["functions"]}
    arm = Arm.from_yaml(yaml_path)
    p, _ = dynamic_parameters(yaml_path, robot.dof)
    model, _ = pinocchio_arm.build(arm, p)
    posts = [pinocchio_arm.split_joint(arm.convention, joint)[1] for joint in arm.joints]
    counts = {f.name()[len(robot.name) + 1:]: int(f.n_instructions())
              for f in casadi_side.controller_functions(model, robot.name)
              + casadi_side.kinematics_functions(model, robot.name, posts, kin.tool_matrix(yaml_path))}
    rows = []
    for cas, ours in {**CONTROLLER, **KINEMATICS}.items():
        o = ops[ours]
        mine = o["mul"] + o["add"] + o["div"]
        best = min(v for k, v in counts.items() if k.split("_", 1)[1] == cas)
        rows.append([robot.name, f"`{ours}`", str(mine), str(counts.get(f"cas_{cas}", "-")),
                     str(counts.get(f"casb_{cas}", "-")), f"{best / mine:.2f}x"])
    return rows


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("--arms", nargs="+", default=None)
    ap.add_argument("--output", default=str(BENCH / "results" / "casadi_counts.md"))
    args = ap.parse_args(argv)
    lines = ["| arm | function | dyngen mul+add+div | CasADi SX instructions (parameters in) | CasADi (baked) | "
             "CasADi best / dyngen |", "|---|---|---:|---:|---:|---:|"]
    for name in args.arms or example_arms():
        log(f"{name} ...")
        lines += ["| " + " | ".join(r) + " |" for r in arm_rows(name)]
    text = "\n".join(lines)
    print(text)
    if args.output:
        Path(args.output).write_text("# Controller and kinematics functions: dyngen's operations vs CasADi's SX "
                                     "instructions\n\nWritten by `python bench/bench_casadi_counts.py`.\n\n" + text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
