#!/usr/bin/env python3
"""Benchmark: dyngen's controller functions against Pinocchio's, instructions per call (callgrind).

Per arm (examples/*.yaml, or --arms): generate the C, build the same arm as a Pinocchio model
(bench_dynamics.prepare_arm), compile ONE executable (generated C + bench/controller_harness.cpp
+ bench/pinocchio_side.cpp + bench/pinocchio_controller.cpp, header-only Pinocchio, the same
compiler and flags), check that both sides agree on every state (relative 1e-9), then count
instructions per call with valgrind (CALLS calls minus a 0-call run, / CALLS) and, with
--time, the median ns/call over batches:

    <arm>_coriolis_matrix                 vs computeCoriolisMatrix
    <arm>_mass_matrix_derivative          vs computeCoriolisMatrix, then C + C^T
    <arm>_regressor_slotine_li            vs computeJointTorqueRegressor (not the same quantity:
                                             Pinocchio has no Slotine-Li regressor; for scale)
    <arm>_forward_dynamics                vs aba
    <arm>_rnea_derivatives                vs computeRNEADerivatives
    <arm>_forward_dynamics_derivatives    vs computeABADerivatives

    python bench/bench_controller.py [--arms lwr panda ...] [--calls 1000] [--time]

The table goes to bench/results/controller.md.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import shlex
import shutil
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from bench_dynamics import (BENCH, DEFAULT_FLAGS, finish_pinocchio_object, markdown, pinocchio_object,
                            pinocchio_toolchain, prepare_arm, run)
from common import arm_yaml, compiler_version, example_arms, log, machine

FUNCTIONS = {  # harness name -> (generated function, Pinocchio's)
    "coriolis": ("coriolis_matrix", "computeCoriolisMatrix"),
    "mass_matrix_dot": ("mass_matrix_derivative", "computeCoriolisMatrix + C + C^T"),
    "slotine_li": ("regressor_slotine_li", "computeJointTorqueRegressor (not Slotine-Li)"),
    "fd": ("forward_dynamics", "aba"),
    "rnea_derivatives": ("rnea_derivatives", "computeRNEADerivatives"),
    "fd_derivatives": ("forward_dynamics_derivatives", "computeABADerivatives"),
}


def controller_object(cxx: str, flags: list, tool: dict) -> Path:
    cmd = [cxx, "-std=c++17", *flags, *(f"-D{d}" for d in tool["defines"]), *(f"-I{i}" for i in tool["includes"]),
           f"-I{BENCH}", "-c", str(BENCH / "pinocchio_controller.cpp")]
    key = hashlib.sha256("\n".join([(BENCH / "pinocchio_controller.cpp").read_text(),
                                    (BENCH / "pinocchio_controller.hpp").read_text(), compiler_version(cxx),
                                    shlex.join(cmd), tool["version"]]).encode()).hexdigest()[:16]
    (BENCH / ".build").mkdir(exist_ok=True)
    obj = BENCH / ".build" / f"pinocchio_controller-{key}.o"
    if not obj.is_file():
        log("compiling pinocchio_controller.cpp (header-only Pinocchio) ...")
        tmp = obj.with_suffix(f".{os.getpid()}.tmp.o")
        run(cmd + ["-o", str(tmp)])
        os.replace(tmp, obj)
    return obj


def arm_inc(a: dict) -> str:
    name, n = a["name"], a["n"]
    numbers = lambda xs: ", ".join(repr(float(x)) for x in xs)  # noqa: E731
    return "\n".join([f'#include "{name}.h"', f"#define ARM(fn) {name}_##fn", f"#define N {n}",
                      f"#define N_PI_FULL {a['shapes']['pi_full'][0]}",
                      f"static const double P[{10 * n}] = {{{numbers(a['p'])}}};",
                      f"static const double QLO[{n}] = {{{numbers(a['qlo'])}}};",
                      f"static const double QHI[{n}] = {{{numbers(a['qhi'])}}};", ""])


def build(a: dict, work: Path, cc: str, cxx: str, flags: list, pin_objs: list) -> Path:
    folder, objs = a["folder"], []
    out = work / a["name"]
    out.mkdir(parents=True, exist_ok=True)
    for src in sorted(folder.glob(f"{a['name']}_*.c")):
        if src.name.endswith("_selftest.c"):
            continue
        obj = out / (src.stem + ".o")
        run([cc, "-std=c99", *flags, "-c", str(src), "-o", str(obj)])
        objs.append(obj)
    (out / "arm.inc").write_text(arm_inc(a))
    harness = out / "controller_harness.o"
    run([cxx, "-std=c++17", *flags, f"-I{out}", f"-I{BENCH}", f"-I{folder}", "-c",
         str(BENCH / "controller_harness.cpp"), "-o", str(harness)])
    exe = out / "controller_bench"
    run([cxx, *flags, str(harness), *map(str, pin_objs), *map(str, objs), "-o", str(exe), "-lm"])
    return exe


def instructions(exe: Path, model: Path, states: int, fn: str, side: str, calls: int, work: Path) -> int:
    out = work / f"callgrind.{exe.parent.name}.{fn}.{side}.{calls}.out"
    run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(exe), "callgrind", str(model),
         str(states), fn, side, str(calls)])
    for line in out.read_text().splitlines():
        if line.startswith(("summary:", "totals:")):
            return int(line.split()[1])
    raise SystemExit(f"no instruction total in {out}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--arms", nargs="+", default=None)
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--states", type=int, default=100)
    ap.add_argument("--time", action="store_true", help="also time (median ns/call over batches)")
    ap.add_argument("--batches", type=int, default=50)
    ap.add_argument("--flags", default=DEFAULT_FLAGS)
    ap.add_argument("--output", default=str(BENCH / "results" / "controller.md"))
    args = ap.parse_args(argv)
    if not shutil.which("valgrind"):
        raise SystemExit("needs valgrind")
    cc, cxx = os.environ.get("CC", "gcc"), os.environ.get("CXX", "g++")
    flags = shlex.split(args.flags)
    tool = pinocchio_toolchain()
    side_obj, proc = pinocchio_object(cxx, flags, tool, False, False)
    finish_pinocchio_object(proc)
    pin_objs = [side_obj, controller_object(cxx, flags, tool)]
    work = Path(tempfile.mkdtemp(prefix="dyngen-controller-bench-"))
    rows = [["arm", "dyngen", "Pinocchio", "dyngen mul", "dyngen add", "dyngen div", "dyngen Ir/call",
             "Pinocchio Ir/call", "Ir ratio"] + (["dyngen ns", "Pinocchio ns"] if args.time else [])]
    try:
        for name in args.arms or example_arms():
            log(f"{name}: generating and compiling ...")
            (work / "gen").mkdir(exist_ok=True)
            (work / "models").mkdir(exist_ok=True)
            a = prepare_arm(arm_yaml(name), work / "gen", work / "models")
            exe = build(a, work, cc, cxx, flags, pin_objs)
            model = work / "models" / f"{a['name']}.model"
            verified = run([str(exe), "verify", str(model), str(args.states)]).stdout
            log(verified.strip())
            times = {}
            if args.time:
                for line in run([str(exe), "time", str(model), str(args.states), str(args.batches)]).stdout.splitlines():
                    tok = line.split()
                    times[tok[1]] = (float(tok[2]), float(tok[3]))
            jobs = [("coriolis", "dyngen", 0)] + [(f, side, args.calls) for f in FUNCTIONS for side in ("dyngen", "pinocchio")]
            with ThreadPoolExecutor(max_workers=2) as pool:
                irs = dict(zip(jobs, pool.map(lambda j: instructions(exe, model, args.states, *j, work), jobs)))
            base = irs[("coriolis", "dyngen", 0)]
            for f, (generated, pinocchio) in FUNCTIONS.items():
                d, p = ((irs[(f, side, args.calls)] - base) / args.calls for side in ("dyngen", "pinocchio"))
                ops = a["ops"][generated]
                row = [a["name"], generated, pinocchio, str(ops["mul"]), str(ops["add"]), str(ops["div"]),
                       f"{d:.0f}", f"{p:.0f}", f"{p / d:.2f}x"]
                if args.time:
                    row += [f"{times[f][0]:.0f}", f"{times[f][1]:.0f}"]
                rows.append(row)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    text = markdown(rows)
    print(text)
    if args.output:
        info = [f"- machine: {machine()}", f"- compilers: `{cc}` ({compiler_version(cc)}) and `{cxx}`, flags `{args.flags}`",
                f"- Pinocchio {tool['version']} (header-only, same flags); {args.calls} calls per function and side, "
                f"{args.states} random states, instructions = (run with CALLS calls - run with 0) / CALLS"]
        Path(args.output).write_text("# Controller functions: dyngen vs Pinocchio\n\n" + "\n".join(info) + "\n\n"
                                     + text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
