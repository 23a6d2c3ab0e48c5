#!/usr/bin/env python3
"""Benchmark: the generated kinematics and control functions against Pinocchio (C++).

Per arm (examples/*.yaml, or --arms): generate the C, build the same arm in Pinocchio with
its link frames and the tool frame (tests/oracles/kinematics.py), compile one executable
(generated C + bench/kinematics_harness.cpp + bench/pinocchio_kinematics.cpp, same compiler
and flags), check agreement on every state (1e-9), then time and count instructions:

    link_poses             vs framesForwardKinematics
    flange_pose            vs forwardKinematics + updateFramePlacement
    jacobian               vs computeFrameJacobian (LOCAL_WORLD_ALIGNED)
    link_jacobians         vs computeJointJacobians + getFrameJacobian per link frame
    jacobian_dot_qd        vs forwardKinematics(q, qd, 0) + getFrameClassicalAcceleration
    control                vs computeGeneralizedGravity + crba + nonLinearEffects
    control_with_jacobian  vs the three above + computeFrameJacobian + the classical acceleration

    python bench/bench_kinematics.py [--arms lwr ...] [--callgrind] [--output bench/results/kinematics.md]

The five kinematics functions have a third side in the same binary: CasADi's C of SX forward
kinematics of the same Pinocchio model (bench/casadi_side.py, kinematics_functions; the
Jacobian's linear rows by casadi.jacobian, Jdot qd by casadi.jtimes), cse=True, same flags,
one file per function compiled once into a private cache (bench/casadi_objects.py).

Pinocchio is header-only, compiled once into bench/.build/ (the model is read at run time).
"""
from __future__ import annotations

import hashlib
import json
import os
import shlex
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from common import BENCH, arguments, arm_yaml, compiler_version, example_arms, log, machine, on_path

ROOT = on_path()
from bench_dynamics import dynamic_parameters, fmt, joint_ranges, pinocchio_toolchain, run, write_model  # noqa: E402

PAIRS = {
    "link_poses": "framesForwardKinematics",
    "flange_pose": "forwardKinematics + updateFramePlacement",
    "jacobian": "computeFrameJacobian",
    "link_jacobians": "computeJointJacobians + getFrameJacobian x N",
    "jacobian_dot_qd": "forwardKinematics(q, qd, 0) + getFrameClassicalAcceleration",
    "control": "computeGeneralizedGravity + crba + nonLinearEffects",
    "control_with_jacobian": "control's three + computeFrameJacobian + classical acceleration",
}
DEFAULT_FLAGS = "-O2 -DNDEBUG"
SIDES = ("dyngen", "pinocchio", "casadi")
CASADI_PAIRS = ("link_poses", "flange_pose", "jacobian", "link_jacobians", "jacobian_dot_qd")


def pinocchio_object(cxx: str, flags: list, tool: dict) -> Path:
    sources = [BENCH / "pinocchio_kinematics.cpp", BENCH / "pinocchio_kinematics.hpp"]
    cmd = [cxx, "-std=c++17", *flags, *(f"-D{d}" for d in tool["defines"]), *(f"-I{i}" for i in tool["includes"]),
           f"-I{BENCH}", "-c", str(sources[0])]
    key = hashlib.sha256("\n".join([*(s.read_text() for s in sources), compiler_version(cxx), shlex.join(cmd),
                                    tool["version"]]).encode()).hexdigest()[:16]
    obj = BENCH / ".build" / f"pinocchio_kinematics-{key}.o"
    if not obj.is_file():
        obj.parent.mkdir(exist_ok=True)
        log("compiling pinocchio_kinematics.cpp (header-only Pinocchio, about a minute) ...")
        tmp = obj.with_suffix(f".{os.getpid()}.tmp.o")
        run(cmd + ["-o", str(tmp)])
        os.replace(tmp, obj)
    return obj


def prepare(name: str, work: Path, cc: str, cxx: str, flags: list, pin_obj: Path) -> dict:
    """Generate one arm, write its Pinocchio model with frames, build its executable."""
    from oracles import kinematics as kin
    from oracles import pinocchio_arm
    from oracles.arm import Arm

    from dyngen.generate import generate

    yaml_path = arm_yaml(name)
    folder = generate(yaml_path, work / "gen").folder
    manifest = json.loads((folder / "manifest.json").read_text())
    robot, n = manifest["robot"], manifest["dof"]
    arm = Arm.from_yaml(yaml_path)
    p, p_source = dynamic_parameters(yaml_path, n)
    tool = kin.tool_matrix(yaml_path)
    model, _ = pinocchio_arm.build(arm, p)
    model_file = work / f"{robot}.model"
    write_model(model_file, model)
    posts = [pinocchio_arm.split_joint(arm.convention, joint)[1] for joint in arm.joints]
    frames = [(i + 1, post) for i, post in enumerate(posts)] + [(n, posts[-1] @ tool)]  # link frames, tool
    with open(model_file, "a") as f:
        for joint, T in frames:
            f.write(f"frame {joint}  {fmt(T[:3, :3])}  {fmt(T[:3, 3])}\n")
    lo, hi = joint_ranges(yaml_path)
    build = work / robot
    build.mkdir()
    import casadi_side

    cas_info = casadi_side.generate_kinematics(model, robot, posts, tool, build / "casadi", cc, flags)
    wrappers = []
    for fn, ins in casadi_side.KINEMATICS_FUNCTIONS.items():
        info = cas_info[f"{robot}_casb_{fn}"]
        wrappers += [f"static void casb_{fn}({', '.join(f'const double *{x}' for x in ins)}, double *out) {{",
                     f"  const double *arg[{len(ins)}] = {{{', '.join(ins)}}};", "  double *res[1] = {out};",
                     f"  static casadi_int iw[{max(1, info['iw'])}];", f"  static double w[{max(1, info['w'])}];",
                     f"  {robot}_casb_{fn}(arg, res, iw, w, 0);", "}"]
    (build / "arm.inc").write_text("\n".join([
        f'#include "{robot}.h"', f"#define ARM(fn) {robot}_##fn", f"#define ARM_N {n}",
        f"static const double ARM_P[{10 * n}] = {{{', '.join(map(repr, map(float, p)))}}};",
        f"static const double ARM_QLO[{n}] = {{{', '.join(map(repr, map(float, lo)))}}};",
        f"static const double ARM_QHI[{n}] = {{{', '.join(map(repr, map(float, hi)))}}};",
        *(f'#include "{info["header"].name}"' for info in cas_info.values()), *wrappers, ""]))
    objects = []
    for src in manifest["files"]["library"]:
        obj = build / (Path(src).stem + ".o")
        run([cc, "-std=c99", *flags, "-c", str(folder / src), "-o", str(obj)])
        objects.append(obj)
    objects += [info["object"] for info in cas_info.values()]  # compiled and cached before
    harness = build / "harness.o"
    run([cxx, "-std=c++17", *flags, f"-I{build}", f"-I{BENCH}", f"-I{folder}", f"-I{build / 'casadi'}", "-c",
         str(BENCH / "kinematics_harness.cpp"), "-o", str(harness)])
    exe = build / "kinematics_harness"
    run([cxx, *flags, str(harness), str(pin_obj), *map(str, objects), "-o", str(exe), "-lm"])
    ops = {f["name"][len(robot) + 1:]: f["ops"] for f in manifest["functions"]}
    return {"name": robot, "n": n, "exe": exe, "model": model_file, "ops": ops, "p_source": p_source}


def callgrind(arm: dict, states: int, function: str, side: str, calls: int, work: Path) -> int:
    out = work / f"{arm['name']}.{function}.{side}.{calls}.callgrind"
    run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(arm["exe"]), "count", str(arm["model"]),
         str(states), function, side, str(calls)])
    for line in out.read_text().splitlines():
        if line.startswith(("summary:", "totals:")):
            return int(line.split()[1])
    raise SystemExit(f"no instruction total in {out}")


def measure(arm: dict, args, work: Path) -> dict:
    res = run([str(arm["exe"]), "time", str(arm["model"]), str(args.states), str(args.batches), str(args.warmup)])
    rows = {}
    for line in res.stdout.splitlines():
        tok = line.split()
        if tok[0] == "VERIFY":
            rows.setdefault(tok[1], {})["error"] = float(tok[2])
            if len(tok) > 3:
                rows[tok[1]]["casadi_error"] = float(tok[3])
        elif tok[0] == "TIME":
            rows[tok[1]].update(dyngen_ns=float(tok[2]), pinocchio_ns=float(tok[3]))
            if len(tok) > 4:
                rows[tok[1]]["casadi_ns"] = float(tok[4])
    if args.callgrind:
        jobs = [("link_poses", "dyngen", 0)] + [(f, side, args.calls) for f in PAIRS for side in SIDES
                                                if side != "casadi" or f in CASADI_PAIRS]
        with ThreadPoolExecutor(max_workers=2) as pool:
            irs = dict(zip(jobs, pool.map(lambda j: callgrind(arm, args.states, *j, work), jobs)))
        base = irs[("link_poses", "dyngen", 0)]
        for (f, side, calls) in jobs[1:]:
            rows[f][f"{side}_ir"] = (irs[(f, side, calls)] - base) / calls
    return rows


def markdown(arms: list, results: dict, callgrind: bool) -> str:
    head = "| arm | dyngen | Pinocchio | dyngen ns | Pinocchio ns | ratio | mul | add | sin/cos |"
    rule = "|---|---|---|---:|---:|---:|---:|---:|---:|"
    if callgrind:
        head += " dyngen Ir | Pinocchio Ir | Ir ratio | CasADi ns | CasADi Ir | CasADi Ir / dyngen Ir |"
        rule += "---:|---:|---:|---:|---:|---:|"
    lines = [head, rule]
    for a in arms:
        for f, theirs in PAIRS.items():
            r, ops = results[a["name"]][f], a["ops"][f]
            line = (f"| {a['name']} | `{f}` | {theirs} | {r['dyngen_ns']:.1f} | {r['pinocchio_ns']:.1f} | "
                    f"{r['pinocchio_ns'] / r['dyngen_ns']:.2f}x | {ops['mul']} | {ops['add']} | {ops['sin_cos']} |")
            if callgrind:
                line += f" {r['dyngen_ir']:.0f} | {r['pinocchio_ir']:.0f} | {r['pinocchio_ir'] / r['dyngen_ir']:.2f}x |"
                line += (f" {r['casadi_ns']:.1f} | {r['casadi_ir']:.0f} | {r['casadi_ir'] / r['dyngen_ir']:.2f}x |"
                         if "casadi_ir" in r else " - | - | - |")
            lines.append(line)
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("--arms", nargs="*", help="example names or YAML paths (default: every example arm)")
    ap.add_argument("--states", type=int, default=1000)
    ap.add_argument("--batches", type=int, default=100)
    ap.add_argument("--warmup", type=int, default=5)
    ap.add_argument("--callgrind", action="store_true", help="also count instructions per call with valgrind")
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--flags", default=DEFAULT_FLAGS)
    ap.add_argument("--output", help="markdown file (a .json with the numbers beside it)")
    args = ap.parse_args(argv)
    start = time.perf_counter()
    cc, cxx = os.environ.get("CC", "gcc"), os.environ.get("CXX", "g++")
    flags = shlex.split(args.flags)
    tool = pinocchio_toolchain()
    pin_obj = pinocchio_object(cxx, flags, tool)
    results, arms = {}, []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.arms or example_arms():
            log(f"{name}: generating and building ...")
            arm = prepare(name, Path(tmp), cc, cxx, flags, pin_obj)
            log(f"{name}: verifying, timing{' and counting instructions' if args.callgrind else ''} ...")
            results[arm["name"]] = measure(arm, args, Path(tmp))
            arms.append(arm)
    bad = {(a, f): r["error"] for a, rs in results.items() for f, r in rs.items()
           if not (r["error"] < 1e-9 and r.get("casadi_error", 0.0) < 1e-9)}
    if bad:
        raise SystemExit(f"dyngen or CasADi and Pinocchio disagree: {bad}")
    info = [f"- machine: {machine()}",
            f"- `{cc}` ({compiler_version(cc)}) `-std=c99 {args.flags}` for the generated C; `{cxx}` "
            f"({compiler_version(cxx)}) `-std=c++17 {args.flags}` for the harness and Pinocchio {tool['version']} "
            f"(header-only, Eigen {tool['eigen_version']})",
            f"- {args.states} random states within the joint limits, qd in [-2, 2]; median of {args.batches} "
            "interleaved batches; every call out of line; parameters: "
            + "; ".join(f"{a['name']} {a['p_source']}" for a in arms),
            "- agreement before timing, every state, max |dyngen - Pinocchio| / max(1, |Pinocchio|): "
            + "; ".join(f"{a} " + ", ".join(f"{f} {r['error']:.1e}" for f, r in rs.items()) for a, rs in results.items()),
            "- CasADi (the five kinematics functions) against Pinocchio, same measure: "
            + "; ".join(f"{a} " + ", ".join(f"{f} {r['casadi_error']:.1e}" for f, r in rs.items() if "casadi_error" in r)
                        for a, rs in results.items()),
            "- Pinocchio's control: crba fills the upper triangle of M; c = nonLinearEffects - g"]
    if args.callgrind:
        info.append(f"- Ir: callgrind instructions per call ({args.calls} calls minus a 0-call run, same set-up)")
    text = "\n".join(info) + "\n\n" + markdown(arms, results, args.callgrind) + "\n"
    print(text)
    if args.output:
        out = Path(args.output)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text("# Kinematics and control(): generated C vs Pinocchio and CasADi\n\nWritten by `python "
                       f"bench/bench_kinematics.py{' --callgrind' if args.callgrind else ''}`.\n\n" + text)
        out.with_suffix(".json").write_text(json.dumps(
            {a: {f: {k: v for k, v in r.items()} for f, r in rs.items()} for a, rs in results.items()}, indent=1) + "\n")
        log(f"wrote {out}")
    log(f"done in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
