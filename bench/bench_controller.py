#!/usr/bin/env python3
"""Benchmark: dyngen's controller functions against Pinocchio's and CasADi's, instructions per call (callgrind).

Per arm (examples/*.yaml, or --arms): generate the C, build the same arm as a Pinocchio model
(bench_dynamics.prepare_arm) and as CasADi-generated C (casadi_side.generate_controller: a
plain rnea over casadi.SX, C by Christoffel symbols of casadi.jacobian(M), M_dot by jtimes, FD
by casadi.solve, the derivatives by casadi.jacobian; parameters as input and baked), compile
ONE executable (generated C + CasADi's C, one file per function compiled once into a private
cache by bench/casadi_objects.py, + bench/controller_harness.cpp + bench/pinocchio_side.cpp
+ bench/pinocchio_controller.cpp, header-only Pinocchio, the same compiler and flags), check
that every side agrees with Pinocchio on every state (relative 1e-9; normwise for FD and its
derivatives, controller_harness.cpp says why), then count instructions
per call with valgrind (CALLS calls minus a 0-call run, / CALLS) and, with --time, the median
ns/call over interleaved batches:

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

import hashlib
import os
import shlex
import shutil
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import casadi_side
from bench_dynamics import (BENCH, DEFAULT_FLAGS, finish_pinocchio_object, markdown, pinocchio_object,
                            pinocchio_toolchain, prepare_arm, run)
from common import arguments, arm_yaml, compiler_version, example_arms, log, machine

SIDES = ("dyngen", "pinocchio", "casadi", "casadi_baked")  # the harness's order

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


def casadi_wrappers(a: dict) -> list:
    """cas_<fn>(inputs..., params, out) and casb_<fn>(inputs..., out) over CasADi's calling convention."""
    name, lines = a["name"], []
    for fn, (ins, out) in casadi_side.CONTROLLER_FUNCTIONS.items():
        for variant in casadi_side.VARIANTS:
            if f"{name}_{variant}_{fn}" not in a["casadi_controller"]:
                continue
            info, args = a["casadi_controller"][f"{name}_{variant}_{fn}"], ins + (["params"] if variant == "cas" else [])
            lines += [f"static void {variant}_{fn}({', '.join(f'const double *{x}' for x in args)}, double *{out}) {{",
                      f"  const double *arg[{len(args)}] = {{{', '.join(args)}}};",
                      f"  double *res[1] = {{{out}}};",
                      f"  static casadi_int iw[{max(1, info['iw'])}];",
                      f"  static double w[{max(1, info['w'])}];",
                      f"  {name}_{variant}_{fn}(arg, res, iw, w, 0);",
                      "}"]
    return lines


def casadi_controller(a: dict, yaml_path: Path, cc: str, flags: list) -> dict:
    """CasADi's C of the controller functions for the arm's Pinocchio model, beside its dynamics' C."""
    from oracles import pinocchio_arm
    from oracles.arm import Arm

    model, _ = pinocchio_arm.build(Arm.from_yaml(yaml_path), a["p"])
    return casadi_side.generate_controller(model, a["name"], a["folder"] / "casadi", cc, flags)


def arm_inc(a: dict) -> str:
    name, n = a["name"], a["n"]
    numbers = lambda xs: ", ".join(repr(float(x)) for x in xs)  # noqa: E731
    headers = [f'#include "{info["header"].name}"' for info in a["casadi_controller"].values()]
    return "\n".join([f'#include "{name}.h"', *headers,
                      f"#define ARM(fn) {name}_##fn", f"#define N {n}",
                      f"#define N_PI_FULL {a['shapes']['pi_full'][0]}",
                      f"static const double P[{10 * n}] = {{{numbers(a['p'])}}};",
                      f"static const double QLO[{n}] = {{{numbers(a['qlo'])}}};",
                      f"static const double QHI[{n}] = {{{numbers(a['qhi'])}}};", *casadi_wrappers(a), ""])


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
    objs += [info["object"] for info in a["casadi_controller"].values()]  # compiled and cached before
    cas = folder / "casadi"
    (out / "arm.inc").write_text(arm_inc(a))
    harness = out / "controller_harness.o"
    run([cxx, "-std=c++17", *flags, f"-I{out}", f"-I{BENCH}", f"-I{folder}", f"-I{cas}", "-c",
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


def write_table(args, rows: list, verify_lines: list, cc: str, cxx: str, tool: dict) -> str:
    """The table so far, written to args.output (if any) with how it was measured; returns it."""
    text = markdown(rows)
    if args.output:
        info = [f"- machine: {machine()}", f"- compilers: `{cc}` ({compiler_version(cc)}) and `{cxx}`, flags `{args.flags}`",
                f"- Pinocchio {tool['version']} (header-only, same flags); {args.calls} calls per function and side, "
                f"{args.states} random states, instructions = (run with CALLS calls - run with 0) / CALLS",
                f"- CasADi {casadi_side.ca.__version__}: bench/casadi_side.py (controller_functions), cse=True, one C file "
                "per function (bench/casadi_objects.py), the same flags; \"vs\" columns: the other side's Ir / dyngen's "
                "(> 1: dyngen fewer)", "- agreement with Pinocchio, "
                "max relative error (dyngen, CasADi, CasADi baked): " + "; ".join(verify_lines)]
        Path(args.output).write_text("# Controller functions: dyngen vs Pinocchio and CasADi\n\n" + "\n".join(info) + "\n\n"
                                     + text + "\n")
    return text


def main(argv=None) -> int:
    ap = arguments(__doc__)
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
    verify_lines = []
    rows = [["arm", "dyngen", "Pinocchio", "dyngen mul", "dyngen add", "dyngen div", "dyngen Ir/call",
             "Pinocchio Ir/call", "CasADi Ir/call", "CasADi baked Ir/call", "vs Pinocchio", "vs CasADi (best)"]
            + (["dyngen ns", "Pinocchio ns", "CasADi ns", "CasADi baked ns"] if args.time else [])]
    try:
        for name in args.arms or example_arms():
            log(f"{name}: generating and compiling ...")
            (work / "gen").mkdir(exist_ok=True)
            (work / "models").mkdir(exist_ok=True)
            a = prepare_arm(arm_yaml(name), work / "gen", work / "models")
            a["casadi_controller"] = casadi_controller(a, arm_yaml(name), cc, flags)
            exe = build(a, work, cc, cxx, flags, pin_objs)
            model = work / "models" / f"{a['name']}.model"
            verified = run([str(exe), "verify", str(model), str(args.states)]).stdout
            log(verified.strip())
            verify_lines += [f"{a['name']} {line.split()[1]} " + " / ".join(line.split()[2:]) for line in verified.splitlines()]
            times = {}
            if args.time:
                for line in run([str(exe), "time", str(model), str(args.states), str(args.batches)]).stdout.splitlines():
                    tok = line.split()
                    times[tok[1]] = [float(x) for x in tok[2:6]]
            jobs = [("coriolis", "dyngen", 0)] + [(f, side, args.calls) for f in FUNCTIONS for side in SIDES
                                                  if not (f == "slotine_li" and side == "casadi_baked")]
            with ThreadPoolExecutor(max_workers=2) as pool:
                irs = dict(zip(jobs, pool.map(lambda j: instructions(exe, model, args.states, *j, work), jobs)))
            base = irs[("coriolis", "dyngen", 0)]
            for f, (generated, pinocchio) in FUNCTIONS.items():
                per = {side: (irs[(f, side, args.calls)] - base) / args.calls for side in SIDES if (f, side, args.calls) in irs}
                d, p = per["dyngen"], per["pinocchio"]
                best = min(per["casadi"], per.get("casadi_baked", per["casadi"]))
                ops = a["ops"][generated]
                row = [a["name"], generated, pinocchio, str(ops["mul"]), str(ops["add"]), str(ops["div"]),
                       f"{d:.0f}", f"{p:.0f}", f"{per['casadi']:.0f}",
                       f"{per['casadi_baked']:.0f}" if "casadi_baked" in per else "(= CasADi: Y holds no parameters)",
                       f"{p / d:.2f}x", f"{best / d:.2f}x"]
                if args.time:
                    row += [f"{x:.0f}" for x in times[f]]
                rows.append(row)
            write_table(args, rows, verify_lines, cc, cxx, tool)  # after every arm: a long run keeps what it measured
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(write_table(args, rows, verify_lines, cc, cxx, tool))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
