#!/usr/bin/env python3
"""Benchmark: dyngen's generated C against Pinocchio (C++) on the same arms.

For every example arm (examples/*.yaml, or --arms): generate the C into a temporary folder,
build the same arm as a Pinocchio model (tests/oracles/pinocchio_arm.py, exported to a text
file the C++ side reads), compile ONE executable (generated C + bench/harness.cpp +
bench/pinocchio_side.cpp) with the same compiler family and the same flags on both sides,
check that both sides agree on every state (relative 1e-9), then time, on the same random
states:

    <name>_rnea                                 vs pinocchio::rnea
    <name>_gravity                              vs pinocchio::computeGeneralizedGravity
    <name>_regressor_gravity, then Y_g pi_g     vs pinocchio::computeGeneralizedGravity
    <name>_mass_matrix                          vs pinocchio::crba (upper triangle, as crba fills it)
    <name>_regressor_inertia, then Y_m pi_m     vs pinocchio::crba (Y_m pi_m is the stacked upper triangle)
    <name>_regressor (n x base coefficients)    vs pinocchio::computeJointTorqueRegressor (n x 10n)
    <name>_rnea_nominal (nominal p folded in)   vs pinocchio::rnea (and CasADi baked: like for like)
    <name>_forward_dynamics(q, qd, tau)         vs pinocchio::aba (and CasADi's solve(M, tau - h))

Reported: the median over batches of the per-batch ns/call, the ratio pinocchio/dyngen and
dyngen's operation counts (manifest.json). --callgrind adds instructions per call measured
with valgrind (load independent). The table goes to bench/results/dynamics.md.

    python bench/bench_dynamics.py [--arms lwr panda ...] [--callgrind]

Pinocchio is compiled header-only from the installed `pin` wheel's headers (its compile
definitions are read from the wheel's CMake config), so its algorithms are built by the same
g++ with the same flags; the compiled Pinocchio object does not depend on the arm and is
cached in bench/.build/ (the first run spends about a minute compiling it).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import yaml

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
from common import arguments, arm_yaml, compiler_version, example_arms, log, machine, on_path  # noqa: E402  (bench/ is sys.path[0])
on_path()

from peak_memory import run_measured  # noqa: E402

# The compared pairs, in harness.cpp's order: id -> (what dyngen computes, Pinocchio's function).
PAIRS = {
    "rnea": ("rnea", "rnea"),
    "gravity": ("gravity g(q)", "computeGeneralizedGravity"),
    "yg_pig": ("Y_g(q) pi_g", "computeGeneralizedGravity"),
    "mass_matrix": ("mass_matrix M(q)", "crba"),
    "ym_pim": ("Y_m(q) pi_m", "crba"),
    "regressor": ("base regressor Y(q, qd, qdd)", "computeJointTorqueRegressor"),
    "rnea_nominal": ("rnea_nominal (nominal p folded in)", "rnea"),
    "forward_dynamics": ("forward_dynamics FD(q, qd, tau)", "aba"),
}
FUNCTIONS = tuple(PAIRS)
# A pair that multiplies a generated regressor by its coefficients: (regressor function,
# coefficients). Its operation count adds the dense product, rows x cols multiplications.
PRODUCTS = {"yg_pig": ("regressor_gravity", "pi_gravity"), "ym_pim": ("regressor_inertia", "pi_inertia")}
DEFAULT_FLAGS = "-O2 -DNDEBUG"
SIDES = ("dyngen", "pinocchio", "casadi", "casadi_baked")  # harness.cpp's order
CASADI_FUNCTIONS = ("rnea", "gravity", "mass_matrix", "rnea_nominal", "forward_dynamics")  # pairs with CasADi sides
# CasADi's own functions (rnea_nominal is timed against rnea's; forward_dynamics is bench_controller's fd)
CASADI_CODE = ("rnea", "gravity", "mass_matrix", "forward_dynamics")
# The like-for-like CasADi variant of each dyngen function: parameters read as an input on both
# sides, or folded in as numbers on both; gravity and M have no dyngen variant with the
# parameters folded in, so they meet the better of the two.
LIKE_FOR_LIKE = {"rnea": "CasADi (parameters as input)", "rnea_nominal": "CasADi baked",
                 "gravity": "better CasADi", "mass_matrix": "better CasADi", "forward_dynamics": "better CasADi"}


def run(cmd, **kw) -> subprocess.CompletedProcess:
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if res.returncode != 0:
        raise SystemExit(f"command failed ({res.returncode}): {shlex.join(map(str, cmd))}\n{res.stdout}{res.stderr}")
    return res


# --- the installed Pinocchio, Eigen and Boost (no hard-coded paths) -----------------------

def pinocchio_toolchain() -> dict:
    """Include dirs and compile definitions of the installed Pinocchio (pip wheel `pin`),
    found from the location of the pinocchio Python package and its CMake config."""
    import pinocchio

    prefix = None
    for parent in Path(pinocchio.__file__).resolve().parents:
        if (parent / "include" / "pinocchio" / "algorithm" / "rnea.hpp").is_file():
            prefix = parent
            break
    if prefix is None:
        raise SystemExit("cannot find Pinocchio's C++ headers next to the pinocchio Python package "
                         f"({pinocchio.__file__}); install the `pin` wheel")
    defines, includes = [], [prefix / "include"]
    configs = [p for d in ("lib", "lib64", "share") for p in (prefix / d).glob("**/pinocchio/pinocchioTargets.cmake")]
    if configs:
        text = configs[0].read_text()
        block = re.search(r"set_target_properties\(pinocchio::pinocchio_headers PROPERTIES(.*?)\n\)", text, re.S)
        if block:
            m = re.search(r'INTERFACE_COMPILE_DEFINITIONS "([^"]*)"', block.group(1))
            if m:
                defines = [d for d in m.group(1).split(";") if d and "$<" not in d]
            m = re.search(r'INTERFACE_INCLUDE_DIRECTORIES "([^"]*)"', block.group(1))
            if m:
                includes = [Path(d.replace("${_IMPORT_PREFIX}", str(prefix)))
                            for d in m.group(1).split(";") if d and "$<" not in d]
    if not defines:  # the definitions of pinocchio::pinocchio_headers in the 4.x wheels
        log("warning: pinocchio::pinocchio_headers not found in a CMake config; using the 4.x definitions")
        defines = ["BOOST_MPL_LIMIT_LIST_SIZE=30", "BOOST_MPL_LIMIT_VECTOR_SIZE=30",
                   "BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "BOOST_FUSION_INVOKE_MAX_ARITY=12"]
    if not (prefix / "include" / "boost" / "version.hpp").is_file():
        raise SystemExit(f"no Boost headers in {prefix / 'include'} (the cmeel-boost wheel, a dependency of pin)")
    eigen = find_eigen(prefix)
    includes.append(eigen)
    return {
        "prefix": prefix,
        "version": pinocchio.__version__,
        "defines": defines,
        "includes": includes,
        "eigen": eigen,
        "eigen_version": header_version(eigen / "Eigen" / "src" / "Core" / "util" / "Macros.h",
                                        ("EIGEN_WORLD_VERSION", "EIGEN_MAJOR_VERSION", "EIGEN_MINOR_VERSION")),
        "boost_version": re.search(r'#define BOOST_LIB_VERSION "([^"]+)"',
                                   (prefix / "include" / "boost" / "version.hpp").read_text()).group(1),
    }


def find_eigen(prefix: Path) -> Path:
    """Eigen's headers: the cmeel prefix (pip install cmeel-eigen), else pkg-config eigen3,
    else the usual system folders."""
    candidates = [prefix / "include" / "eigen3", Path(sysconfig.get_paths()["data"]) / "include" / "eigen3"]
    if shutil.which("pkg-config"):
        res = subprocess.run(["pkg-config", "--cflags-only-I", "eigen3"], capture_output=True, text=True)
        if res.returncode == 0:
            candidates += [Path(tok[2:]) for tok in res.stdout.split() if tok.startswith("-I")]
    candidates += [Path("/usr/include/eigen3"), Path("/usr/local/include/eigen3")]
    for c in candidates:
        if (c / "Eigen" / "Core").is_file():
            return c
    raise SystemExit("Eigen headers not found: `pip install cmeel-eigen` (or apt install libeigen3-dev)")


def header_version(path: Path, macros) -> str:
    text = path.read_text(errors="replace")
    parts = []
    for name in macros:
        m = re.search(rf"#define {name} (\d+)", text)
        parts.append(m.group(1) if m else "?")
    return ".".join(parts)


# --- per arm: generated C, the Pinocchio model file, parameters and joint ranges ----------

def dynamic_parameters(yaml_path: Path, n: int) -> tuple[np.ndarray, str]:
    from oracles.arm import nominal_parameters
    from oracles.random_params import random_parameters

    doc = yaml.safe_load(yaml_path.read_text())
    if (doc.get("parameters") or {}).get("nominal"):
        return nominal_parameters(yaml_path), "nominal (YAML)"
    return random_parameters(n, seed=0), "random, physically consistent (seed 0)"


def joint_ranges(yaml_path: Path) -> tuple[list, list]:
    """q ranges of the random states: the YAML's joint limits, else [-pi, pi] (revolute)
    or [-0.5, 0.5] m (prismatic)."""
    from oracles.arm import evaluate

    lo, hi = [], []
    for j in yaml.safe_load(yaml_path.read_text())["joints"]:
        lim = j.get("limits") or {}
        if "lower" in lim and "upper" in lim:
            lo.append(evaluate(lim["lower"]))
            hi.append(evaluate(lim["upper"]))
        elif j["type"] == "revolute":
            lo.append(-np.pi)
            hi.append(np.pi)
        else:
            lo.append(-0.5)
            hi.append(0.5)
    return lo, hi


def fmt(values) -> str:
    return " ".join(repr(float(v)) for v in np.asarray(values, dtype=float).ravel())


def write_model(path: Path, model) -> None:
    """The Pinocchio model as text for pinocchio_side.cpp: per joint its parent, type (RZ or
    PZ), placement in the parent joint's frame (R row-major, t) and body inertia in the joint
    frame (mass, lever = centre of mass, 3x3 inertia about the centre of mass). Every number
    is written with repr() (round-trip exact), so the C++ model is the identical model."""
    lines = [f"joints {model.njoints - 1}", "gravity " + fmt(model.gravity.linear)]
    for j in range(1, model.njoints):
        kind = model.joints[j].shortname()
        jtype = {"JointModelRZ": "RZ", "JointModelPZ": "PZ"}.get(kind)
        if jtype is None:
            raise SystemExit(f"unexpected joint type {kind}")
        M, Y = model.jointPlacements[j], model.inertias[j]
        lines.append(f"joint {model.parents[j]} {jtype}  {fmt(M.rotation)}  {fmt(M.translation)}  "
                     f"{fmt([Y.mass])}  {fmt(Y.lever)}  {fmt(Y.inertia)}")
    path.write_text("\n".join(lines) + "\n")


def prepare_arm(yaml_path: Path, gen_root: Path, model_dir: Path) -> dict:
    from dyngen.generate import generate
    from oracles import pinocchio_arm
    from oracles.arm import Arm

    result = generate(yaml_path, gen_root)
    folder = result.folder
    manifest = json.loads((folder / "manifest.json").read_text())
    name, n = manifest["robot"], manifest["dof"]
    if manifest.get("gravity_symbols"):
        raise SystemExit(f"{name}: symbolic gravity {manifest['gravity_symbols']} is not supported here")
    p, p_source = dynamic_parameters(yaml_path, n)
    model, _ = pinocchio_arm.build(Arm.from_yaml(yaml_path), p)
    write_model(model_dir / f"{name}.model", model)
    import casadi_side

    casadi = casadi_side.generate(model, name, folder / "casadi")
    ops = {f["name"][len(name) + 1:]: f["ops"] for f in manifest["functions"]}
    shapes = {f["name"][len(name) + 1:]: f["output"]["shape"] for f in manifest["functions"]}
    lo, hi = joint_ranges(yaml_path)
    return {"name": name, "n": n, "folder": folder, "p": p, "p_source": p_source, "ops": ops, "shapes": shapes,
            "casadi": casadi, "model": model,
            "qlo": lo, "qhi": hi, "joint_types": "".join("R" if t == "revolute" else "P"
                                                         for t in manifest["joint_types"])}


def arms_inc(arms: list) -> str:
    import casadi_side

    out = ["// Written by bench_dynamics.py: the arms of this run.", ""]
    for a in arms:
        name, n = a["name"], a["n"]
        cas = []
        for variant in casadi_side.VARIANTS:
            for fn in casadi_side.FUNCTIONS:
                info = a["casadi"][f"{name}_{variant}_{fn}"]
                ins = {"rnea": ["q", "qd", "qdd"], "gravity": ["q"], "mass_matrix": ["q"]}[fn]
                if variant == "cas":
                    ins.append("params")
                out_name = {"rnea": "tau", "gravity": "g", "mass_matrix": "M"}[fn]
                cas += [
                    f"  static void {variant}_{fn}({', '.join(f'const double *{x}' for x in ins)}, double *{out_name}) {{",
                    f"    const double *arg[{len(ins)}] = {{{', '.join(ins)}}};",
                    f"    double *res[1] = {{{out_name}}};",
                    f"    static casadi_int iw[{max(1, info['iw'])}];",
                    f"    static double w[{max(1, info['w'])}];",
                    f"    {name}_{variant}_{fn}(arg, res, iw, w, 0);",
                    "  }",
                ]
        for variant in casadi_side.VARIANTS:  # bench_controller's fd, one object each (casadi_objects.py)
            info, ins = a["casadi_fd"][f"{name}_{variant}_fd"], ["q", "qd", "tau"] + (["params"] if variant == "cas" else [])
            cas += [f"  static void {variant}_fd({', '.join(f'const double *{x}' for x in ins)}, double *qdd) {{",
                    f"    const double *arg[{len(ins)}] = {{{', '.join(ins)}}};",
                    "    double *res[1] = {qdd};",
                    f"    static casadi_int iw[{max(1, info['iw'])}];",
                    f"    static double w[{max(1, info['w'])}];",
                    f"    {name}_{variant}_fd(arg, res, iw, w, 0);",
                    "  }"]
        out += [
            f'#include "{name}.h"',
            f'#include "{name}_casadi.h"',
            *(f'#include "{a["casadi_fd"][f"{name}_{v}_fd"]["header"].name}"' for v in casadi_side.VARIANTS),
            f"struct Arm_{name} {{",
            f'  static constexpr const char *name = "{name}";',
            f"  static constexpr int n = {n};",
            f"  static const double p[{10 * n}];",
            f"  static const double qlo[{n}];",
            f"  static const double qhi[{n}];",
            f"  static void std_from_dyn(const double *p, double *s) {{ {name}_standard_from_dynamic(p, s); }}",
            "  static void rnea(const double *q, const double *qd, const double *qdd, const double *s, double *tau) {",
            f"    {name}_rnea(q, qd, qdd, s, tau);",
            "  }",
            "  static void rnea_nominal(const double *q, const double *qd, const double *qdd, double *tau) {",
            f"    {name}_rnea_nominal(q, qd, qdd, tau);",
            "  }",
            "  static void forward_dynamics(const double *q, const double *qd, const double *tau, const double *s, "
            "double *qdd) {",
            f"    {name}_forward_dynamics(q, qd, tau, s, qdd);",
            "  }",
            f"  static void gravity(const double *q, const double *s, double *g) {{ {name}_gravity(q, s, g); }}",
            f"  static void mass_matrix(const double *q, const double *s, double *M) {{ {name}_mass_matrix(q, s, M); }}",
            f"  static constexpr int n_stacked = {a['shapes']['regressor_inertia'][0]};",
            f"  static constexpr int n_pi_gravity = {a['shapes']['pi_gravity'][0]};",
            f"  static constexpr int n_pi_inertia = {a['shapes']['pi_inertia'][0]};",
            f"  static constexpr int n_pi_full = {a['shapes']['pi_full'][0]};",
            f"  static void pi_gravity(const double *p, double *pi) {{ {name}_pi_gravity(p, pi); }}",
            f"  static void pi_inertia(const double *p, double *pi) {{ {name}_pi_inertia(p, pi); }}",
            f"  static void pi_full(const double *p, double *pi) {{ {name}_pi_full(p, pi); }}",
            f"  static void regressor_gravity(const double *q, double *Y) {{ {name}_regressor_gravity(q, Y); }}",
            f"  static void regressor_inertia(const double *q, double *Y) {{ {name}_regressor_inertia(q, Y); }}",
            "  static void regressor(const double *q, const double *qd, const double *qdd, double *Y) {",
            f"    {name}_regressor(q, qd, qdd, Y);",
            "  }",
            *cas,
            "};",
            f"const double Arm_{name}::p[{10 * n}] = {{{', '.join(repr(float(x)) for x in a['p'])}}};",
            f"const double Arm_{name}::qlo[{n}] = {{{', '.join(repr(float(x)) for x in a['qlo'])}}};",
            f"const double Arm_{name}::qhi[{n}] = {{{', '.join(repr(float(x)) for x in a['qhi'])}}};",
            "",
        ]
    out.append("#define BENCH_ARMS(X) " + " ".join(f"X(Arm_{a['name']})" for a in arms))
    return "\n".join(out) + "\n"


# --- build --------------------------------------------------------------------------------

def pinocchio_library(tool: dict) -> Path:
    """The folder of the wheel's libpinocchio_default.so (precompiled instantiations)."""
    for lib in sorted(tool["prefix"].glob("lib*/libpinocchio_default.so*")):
        return lib.parent
    raise SystemExit(f"libpinocchio_default.so not found under {tool['prefix']}")


def wheel_compiler(tool: dict) -> str:
    """The compiler that built libpinocchio_default (its .comment section), if readable."""
    lib = pinocchio_library(tool) / "libpinocchio_default.so"
    try:
        found = sorted(set(re.findall(rb"GCC: \([^)]*\) [0-9][^\x00]*", lib.read_bytes())))
    except OSError:
        found = []
    return ", ".join(f.decode(errors="replace") for f in found) or "an unknown compiler"


def pinocchio_object(cxx: str, flags: list, tool: dict, rebuild: bool, use_lib: bool):
    """(object path, Popen or None): the compiled pinocchio_side.cpp, from the cache in
    bench/.build/ when the sources, compiler, flags and library versions are unchanged.
    use_lib: declare Pinocchio's explicit instantiations extern (as its CMake target
    pinocchio::pinocchio_default does), so rnea, crba, ... run from the wheel's library."""
    extra = ["PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION"] if use_lib else []
    cmd = [cxx, "-std=c++17", *flags, *(f"-D{d}" for d in [*tool["defines"], *extra]),
           *(f"-I{i}" for i in tool["includes"]), "-c", str(BENCH / "pinocchio_side.cpp")]
    key = hashlib.sha256("\n".join([
        (BENCH / "pinocchio_side.cpp").read_text(), (BENCH / "pinocchio_side.hpp").read_text(),
        compiler_version(cxx), shlex.join(cmd), tool["version"], tool["eigen_version"], tool["boost_version"],
    ]).encode()).hexdigest()[:16]
    cache = BENCH / ".build"
    cache.mkdir(exist_ok=True)
    obj = cache / f"pinocchio_side-{key}.o"
    if obj.is_file() and not rebuild:
        log(f"Pinocchio side: cached {obj.relative_to(ROOT)}")
        return obj, None
    log("Pinocchio side: compiling pinocchio_side.cpp (header-only Pinocchio, about a minute) ...")
    tmp = cache / f"pinocchio_side-{key}.{os.getpid()}.tmp.o"
    proc = subprocess.Popen(cmd + ["-o", str(tmp)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    proc.bench_cmd, proc.bench_tmp, proc.bench_obj = cmd, tmp, obj
    return obj, proc


def finish_pinocchio_object(proc) -> None:
    if proc is None:
        return
    out, _ = proc.communicate()
    if proc.returncode != 0:
        raise SystemExit(f"compiling the Pinocchio side failed:\n{shlex.join(proc.bench_cmd)}\n{out}")
    os.replace(proc.bench_tmp, proc.bench_obj)


def build(arms: list, work: Path, cc: str, cxx: str, flags: list, pin_obj: Path, pin_proc, libs: list,
          tool: dict) -> Path:
    import casadi_side
    from bench_controller import controller_object  # pin_aba; bench_controller imports this module

    objs = [controller_object(cxx, flags, tool)]
    for a in arms:
        a["casadi_fd"] = casadi_side.generate_controller(a["model"], a["name"], a["folder"] / "casadi", cc, flags,
                                                         which=("fd",))
        objs += [info["object"] for info in a["casadi_fd"].values()]
        for src in (f"{a['name']}_dynamics.c", f"{a['name']}_parameters.c", f"{a['name']}_regressors.c",
                    f"{a['name']}_forward.c"):
            obj = work / "obj" / (src[:-2] + ".o")
            run([cc, "-std=c99", *flags, "-c", str(a["folder"] / src), "-o", str(obj)])
            objs.append(obj)
        obj = work / "obj" / f"{a['name']}_casadi.o"
        run([cc, "-std=c99", *flags, "-c", str(a["folder"] / "casadi" / f"{a['name']}_casadi.c"), "-o", str(obj)])
        objs.append(obj)
    (work / "arms.inc").write_text(arms_inc(arms))
    harness = work / "obj" / "harness.o"
    run([cxx, "-std=c++17", *flags, f"-I{work}", f"-I{BENCH}", *(f"-I{a['folder']}" for a in arms),
         *(f"-I{a['folder'] / 'casadi'}" for a in arms),
         "-c", str(BENCH / "harness.cpp"), "-o", str(harness)])
    finish_pinocchio_object(pin_proc)
    exe = work / "bench_dynamics"
    run([cxx, *flags, str(harness), str(pin_obj), *map(str, objs), "-o", str(exe), *libs, "-lm"])
    return exe


# --- measurements -------------------------------------------------------------------------

def timing(exe: Path, models: Path, states: int, batches: int, warmup: int) -> tuple[dict, dict, tuple]:
    """(times, agreement errors, (peak RSS of the timing run, the launcher's floor) in MiB)."""
    res = run_measured([exe, "time", models, states, batches, warmup])
    times, errors = {}, {}
    for line in res.stdout.splitlines():
        tok = line.split()
        if tok and tok[0] == "TIME":
            times[(tok[1], tok[2])] = tuple(float(x) for x in tok[3:7])
        elif tok and tok[0] == "VERIFY":
            errors[(tok[1], tok[2])] = float(tok[3])
    if res.returncode != 0:
        raise SystemExit(f"benchmark run failed ({res.returncode}):\n{res.stdout}{res.stderr}")
    return times, errors, (res.max_rss_mib, res.floor_kib / 1024)


LIBM = re.compile(r"sysdeps/ieee754|fenv_private|libm\.so")  # callgrind_annotate lines of libm's sin/cos


def callgrind_ir(exe: Path, models: Path, states: int, arm: str, function: str, side: str, calls: int,
                 work: Path) -> tuple[int, int]:
    """(total Ir, Ir inside libm) of one run."""
    out = work / "callgrind" / f"{arm}.{function}.{side}.{calls}.out"
    run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(exe), "callgrind", str(models),
         str(states), arm, function, side, str(calls)])
    libm = 0
    if shutil.which("callgrind_annotate"):
        listing = run(["callgrind_annotate", "--threshold=100", str(out)]).stdout
        for line in listing.splitlines():
            m = re.match(r"\s*([\d,]+)\s", line)
            if m and LIBM.search(line):
                libm += int(m.group(1).replace(",", ""))
    for line in out.read_text().splitlines():
        if line.startswith(("summary:", "totals:")):
            return int(line.split()[1]), libm
    raise SystemExit(f"no instruction total in {out}")


TRIG_PROBE = r"""
#include "{name}.h"
#include <stdlib.h>
volatile double sink;
int main(int argc, char **argv) {{
  long calls = argc > 1 ? atol(argv[1]) : 0;
  double acc = 0.0;
  for (long c = 0; c < calls; ++c) {{
    {real} s, co;
    {macro}_SINCOS(0.001 * (double)c - 1.3, &s, &co);
    acc += s + co;
  }}
  sink = acc;
  return 0;
}}
"""


def sincos_ir(arm: dict, cc: str, flags: list, work: Path, calls: int) -> float:
    """Instructions per angle of the generated code's own sincos (<M>_SINCOS of the arm's header),
    from a small probe program: (Ir of `calls` angles - Ir of 0) / calls."""
    src = work / "trig_probe.c"
    src.write_text(TRIG_PROBE.format(name=arm["name"], real=f"{arm['name']}_real", macro=arm["name"].upper()))
    exe = work / "trig_probe"
    run([cc, "-std=c99", *flags, f"-I{arm['folder']}", str(src), "-o", str(exe), "-lm"])
    total = []
    for k in (calls, 0):
        out = work / f"trig_probe.{k}.out"
        run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(exe), str(k)])
        total.append(next(int(line.split()[1]) for line in out.read_text().splitlines()
                          if line.startswith(("summary:", "totals:"))))
    return (total[0] - total[1]) / calls


def sides_of(function: str) -> tuple:
    return SIDES if function in CASADI_FUNCTIONS else SIDES[:2]


def callgrind_all(exe: Path, models: Path, states: int, arms: list, calls: int, work: Path) -> dict:
    """{(arm, function): (dyngen, pinocchio, casadi, casadi_baked Ir/call; nan where a side does not
    exist)}: (Ir of `calls` calls minus Ir of the same run with 0 calls) / calls."""
    if not shutil.which("valgrind"):
        raise SystemExit("--callgrind needs valgrind")
    (work / "callgrind").mkdir(exist_ok=True)
    jobs = [(a["name"], "rnea", "dyngen", 0) for a in arms]
    jobs += [(a["name"], f, side, calls) for a in arms for f in FUNCTIONS for side in sides_of(f)]
    with ThreadPoolExecutor(max_workers=max(1, min(2, os.cpu_count() or 1))) as pool:
        irs = dict(zip(jobs, pool.map(lambda j: callgrind_ir(exe, models, states, *j, work), jobs)))
    out, libm = {}, {}
    for a in arms:
        base, base_libm = irs[(a["name"], "rnea", "dyngen", 0)]
        for f in FUNCTIONS:
            out[(a["name"], f)] = tuple((irs[(a["name"], f, side, calls)][0] - base) / calls
                                        if side in sides_of(f) else float("nan") for side in SIDES)
            libm[(a["name"], f)] = tuple((irs[(a["name"], f, side, calls)][1] - base_libm) / calls
                                         if side in sides_of(f) else float("nan") for side in SIDES)
    return out, libm


# --- report -------------------------------------------------------------------------------

def pair_ops(arm: dict, pair: str) -> dict:
    """dyngen's operation counts of a pair's timed work: the generated function's (manifest),
    plus, for Y pi, the dense product (rows x cols multiplications, rows x (cols - 1) additions)."""
    if pair not in PRODUCTS:
        return dict(arm["ops"][pair])
    regressor, _ = PRODUCTS[pair]
    rows, cols = arm["shapes"][regressor]
    ops = dict(arm["ops"][regressor])
    ops["mul"] += rows * cols
    ops["add"] += rows * (cols - 1)
    return ops


def table(arms: list, times: dict, irs: dict | None) -> list:
    head = ["arm", "dyngen", "Pinocchio", "dyngen ns/call", "Pinocchio ns/call", "ratio (Pin/dyngen)",
            "dyngen mul", "dyngen add"]
    if irs:
        head += ["dyngen Ir/call", "Pinocchio Ir/call", "Ir ratio"]
    rows = [head]
    for a in arms:
        for f in FUNCTIONS:
            d, p = times[(a["name"], f)][:2]
            ops = pair_ops(a, f)
            row = [a["name"], PAIRS[f][0], PAIRS[f][1], f"{d:.1f}", f"{p:.1f}", f"{p / d:.2f}x",
                   str(ops["mul"]), str(ops["add"])]
            if irs:
                di, pi = irs[(a["name"], f)][:2]
                row += [f"{di:.0f}", f"{pi:.0f}", f"{pi / di:.2f}x"]
            rows.append(row)
    return rows


GOAL_CASADI, GOAL_PINOCCHIO = 1.5, 3.0  # issue 24: fewer instructions than the better CasADi, Pinocchio


def casadi_table(arms: list, times: dict, irs: dict | None, libm: dict | None) -> list:
    """dyngen against both CasADi variants (and Pinocchio) on rnea, gravity and M."""
    head = ["arm", "function", "dyngen ns", "CasADi ns", "CasADi baked ns", "Pinocchio ns"]
    if irs:
        head += ["dyngen Ir", "CasADi Ir", "CasADi baked Ir", "Pinocchio Ir", "best CasADi / dyngen",
                 "compared with", "CasADi / dyngen", "Pinocchio / dyngen", f"goals {GOAL_CASADI}x, {GOAL_PINOCCHIO}x",
                 "sin/cos Ir: dyngen / CasADi / baked", "compared CasADi / dyngen without sin/cos"]
    rows = [head]
    for a in arms:
        for f in CASADI_FUNCTIONS:
            d, p, c, cb = times[(a["name"], f)]
            row = [a["name"], f, f"{d:.1f}", f"{c:.1f}", f"{cb:.1f}", f"{p:.1f}"]
            if irs:
                di, pi, ci, cbi = irs[(a["name"], f)]
                best = {"rnea": ci, "rnea_nominal": cbi}.get(f, min(ci, cbi))  # the like-for-like pair
                missed = [f"CasADi {best / di:.2f}x of {GOAL_CASADI}x (dyngen needs {di - best / GOAL_CASADI:.0f} Ir less)"
                          if best / di < GOAL_CASADI else "",
                          f"Pinocchio {pi / di:.2f}x of {GOAL_PINOCCHIO}x (dyngen needs {di - pi / GOAL_PINOCCHIO:.0f} Ir less)"
                          if pi / di < GOAL_PINOCCHIO else ""]
                li = libm[(a["name"], f)]
                own = {"rnea": ci - li[2], "rnea_nominal": cbi - li[3]}.get(f, min(ci - li[2], cbi - li[3])) / (di - li[0])
                row += [f"{di:.0f}", f"{ci:.0f}", f"{cbi:.0f}", f"{pi:.0f}", f"{min(ci, cbi) / di:.2f}x",
                        LIKE_FOR_LIKE[f], f"{best / di:.2f}x", f"{pi / di:.2f}x",
                        ("missed: " + ", ".join(m for m in missed if m)) if any(missed) else "met",
                        f"{li[0]:.0f} / {li[2]:.0f} / {li[3]:.0f}", f"{own:.2f}x"]
            rows.append(row)
    return rows


def write_json(path: Path, arms: list, times: dict, irs: dict | None, errors: dict, peak: tuple,
               args) -> None:
    """The same numbers, machine-readable (bench/run_all.py reads them for its summary)."""
    doc = {"callgrind": bool(irs), "flags": args.flags, "peak_rss_mib": peak[0], "peak_rss_floor_mib": peak[1],
           "arms": {}}
    for a in arms:
        doc["arms"][a["name"]] = {
            "dof": a["n"],
            "regressor_shape": {"dyngen": a["shapes"]["regressor"], "pinocchio": [a["n"], 10 * a["n"]]},
            "pairs": {f: {"dyngen_ns": times[(a["name"], f)][0], "pinocchio_ns": times[(a["name"], f)][1],
                          "dyngen_ir": irs[(a["name"], f)][0] if irs else None,
                          "pinocchio_ir": irs[(a["name"], f)][1] if irs else None,
                          **({"casadi_ns": times[(a["name"], f)][2], "casadi_baked_ns": times[(a["name"], f)][3],
                              "casadi_ir": irs[(a["name"], f)][2] if irs else None,
                              "casadi_baked_ir": irs[(a["name"], f)][3] if irs else None,
                              "casadi_max_rel_error": errors[(a["name"], f"casadi_{_code(f)}")],
                              "casadi_baked_max_rel_error": errors[(a["name"], f"casadi_baked_{_code(f)}")]}
                             if f in CASADI_FUNCTIONS else {}),
                          "max_rel_error": errors[(a["name"], f)], "ops": pair_ops(a, f)}
                      for f in FUNCTIONS},
        }
    path.write_text(json.dumps(doc, indent=1) + "\n")


def _code(function: str) -> str:
    """The CasADi function a pair is timed against."""
    return function if function in CASADI_CODE else "rnea"


def casadi_version() -> str:
    import casadi

    return casadi.__version__


def markdown(rows: list) -> str:
    right = [False, False, False] + [True] * (len(rows[0]) - 3)
    lines = ["| " + " | ".join(rows[0]) + " |",
             "|" + "|".join("---:" if r else "---" for r in right) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows[1:]]
    return "\n".join(lines)


def plain(rows: list) -> str:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return "\n".join("  ".join(c.ljust(w) if i < 3 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths)))
                     for r in rows)


def main(argv=None) -> int:
    args = parse_args(argv)
    runs = [args]
    if args.native:  # the same again with -march=native, into <output>_native.md, summarised in <output>
        native = argparse.Namespace(**vars(args))
        # valgrind cannot run AVX-512 instructions (vex: unhandled EVEX prefix), so callgrind
        # needs them off; the rest of the host's instruction set stays on
        native.flags = args.flags + " -march=native" + (" -mno-avx512f" if args.callgrind else "")
        native.output = str(Path(args.output).with_name(Path(args.output).stem + "_native.md")) if args.output else ""
        native.keep = str(Path(args.keep) / "native") if args.keep else None
        runs.append(native)
    for run_args in runs:
        work = Path(run_args.keep).resolve() if run_args.keep else Path(tempfile.mkdtemp(prefix="dyngen-bench-"))
        try:
            rc = bench(run_args, work)
        finally:
            if not run_args.keep:
                shutil.rmtree(work, ignore_errors=True)
        if rc:
            return rc
    if args.native and args.output:
        main_md, native_md = Path(args.output), Path(runs[1].output)
        text = native_md.read_text()
        start = text.index("## dyngen vs CasADi-generated C")
        main_md.write_text(main_md.read_text() + f"\n## The same with `{runs[1].flags}`\n\n"
                           f"Written by the same command into {native_md.name}; its CasADi table:\n\n"
                           + text[start:].split("\n", 2)[2])
    return 0


def parse_args(argv):
    ap = arguments(__doc__)
    ap.add_argument("--arms", nargs="+", default=None,
                    help="example names (examples/NAME.yaml) or YAML paths; default: all examples")
    ap.add_argument("--callgrind", action="store_true", help="also count instructions per call with valgrind")
    ap.add_argument("--calls", type=int, default=1000, help="calls per function under callgrind (default 1000)")
    ap.add_argument("--states", type=int, default=1000, help="random states per batch (default 1000)")
    ap.add_argument("--batches", type=int, default=200, help="timed batches per function and side (default 200)")
    ap.add_argument("--warmup", type=int, default=10, help="untimed batches first (default 10)")
    ap.add_argument("--flags", default=DEFAULT_FLAGS,
                    help=f"compiler flags, the same for both sides (default: {DEFAULT_FLAGS!r})")
    ap.add_argument("--pinocchio-lib", action="store_true",
                    help="time the wheel's precompiled Pinocchio algorithms (libpinocchio_default, built by the "
                         "wheel's own compiler and flags) instead of compiling Pinocchio's headers with --flags")
    ap.add_argument("--rebuild", action="store_true", help="recompile the cached Pinocchio side")
    ap.add_argument("--native", action="store_true",
                    help="run again with --flags plus -march=native (with --callgrind also -mno-avx512f, which "
                         "valgrind cannot run; results in <output>_native.md, its CasADi table appended to <output>)")
    ap.add_argument("--keep", metavar="DIR", help="build in DIR and keep it (default: a temporary folder)")
    ap.add_argument("--output", default=str(BENCH / "results" / "dynamics.md"),
                    help="markdown results file (default bench/results/dynamics.md); '' to skip")
    return ap.parse_args(argv)


def bench(args, work: Path) -> int:
    start = time.perf_counter()
    cc, cxx = os.environ.get("CC", "gcc"), os.environ.get("CXX", "g++")
    flags = shlex.split(args.flags)
    tool = pinocchio_toolchain()
    pin_obj, pin_proc = pinocchio_object(cxx, flags, tool, args.rebuild, args.pinocchio_lib)
    libs = []
    if args.pinocchio_lib:
        libdir = pinocchio_library(tool)
        libs = [f"-L{libdir}", "-lpinocchio_default", f"-Wl,-rpath,{libdir}"]
    try:
        names = args.arms or example_arms()
        for sub in ("gen", "models", "obj"):
            (work / sub).mkdir(parents=True, exist_ok=True)
        arms = []
        for name in names:
            log(f"generating {name} ...")
            arms.append(prepare_arm(arm_yaml(name), work / "gen", work / "models"))
        log("compiling the benchmark ...")
        exe = build(arms, work, cc, cxx, flags, pin_obj, pin_proc, libs, tool)
        pin_proc = None
    finally:
        if pin_proc is not None and pin_proc.poll() is None:
            pin_proc.kill()
            pin_proc.wait()

    log(f"verifying and timing ({args.states} states x {args.batches} batches per function and side) ...")
    times, errors, (peak_mib, floor_mib) = timing(exe, work / "models", args.states, args.batches, args.warmup)
    irs = None
    if args.callgrind:
        log(f"callgrind ({args.calls} calls per function and side, minus a 0-call baseline) ...")
        irs, libm = callgrind_all(exe, work / "models", args.states, arms, args.calls, work)
        per_angle = sincos_ir(arms[0], cc, flags, work, args.calls)
        for a in arms:  # dyngen's own sincos, counted like libm's so that 'without' means the same
            for f in CASADI_FUNCTIONS:
                li = list(libm[(a["name"], f)])
                li[0] = per_angle * a["ops"][f]["sin_cos"]
                libm[(a["name"], f)] = tuple(li)
    rows = table(arms, times, irs)
    cas_rows = casadi_table(arms, times, irs, libm if irs else None)

    cc_v, cxx_v = compiler_version(cc), compiler_version(cxx)
    import dyngen  # which generator wrote the C: this checkout's (common.on_path puts it first)

    info = [
        f"- machine: {machine()}",
        f"- generator: dyngen from `{Path(dyngen.__file__).resolve().parent}`",
        f"- C compiler: `{cc}` ({cc_v}), `-std=c99 {args.flags}` (generated C)",
        f"- C++ compiler: `{cxx}` ({cxx_v}), `-std=c++17 {args.flags}` (harness and Pinocchio)",
        (f"- Pinocchio {tool['version']} (pip wheel `pin`), PRECOMPILED: the algorithms "
         f"that have explicit instantiations run from the wheel's {pinocchio_library(tool) / 'libpinocchio_default.so'} (built by "
         f"{wheel_compiler(tool)} with the wheel's flags, NOT the flags above); definitions "
         f"{' '.join('-D' + d for d in tool['defines'])} -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION"
         if args.pinocchio_lib else
         f"- Pinocchio {tool['version']} (pip wheel `pin`), header-only: its algorithms are compiled here with the "
         f"flags above, not taken from the wheel's precompiled library; definitions "
         f"{' '.join('-D' + d for d in tool['defines'])}"),
        f"- Eigen {tool['eigen_version']} ({tool['eigen']}), Boost {tool['boost_version'].replace('_', '.')}",
        f"- {args.states} random states within the joint limits (qd in [-2, 2], qdd in [-5, 5]), "
        f"the same for both sides; {args.batches} timed batches per function and side after {args.warmup} "
        "warm-up batches, interleaved; ns/call = median over batches of (batch time / states)",
        "- every call is an out-of-line call into another translation unit on both sides; the outputs are "
        "summed into a volatile sink (for the inertia matrix: the upper triangle on both sides; for the "
        "regressors only their first and last entries, since summing hundreds of entries would cost more "
        "than the generated regressor itself)",
        "- crba fills only the upper triangle of M; the generated mass matrix writes the full matrix",
        "- Y_g pi_g and Y_m pi_m: the generated regressor, then a plain dense matrix-vector product with the "
        "base coefficients (computed once from p by the generated pi functions), both inside the timed call; "
        "their mul/add columns include the product (rows x cols multiplications). Y_m pi_m is the stacked "
        "upper triangle of M (M11, M12, ..., MNN), compared with crba's upper triangle",
        "- the regressors are different matrices: dyngen's is the BASE regressor, n x (number of base "
        "coefficients), Pinocchio's computeJointTorqueRegressor is n x 10n (all standard parameters, "
        "structurally rank deficient): " + "; ".join(
            f"{a['name']} {a['n']} x {a['shapes']['regressor'][1]} vs {a['n']} x {10 * a['n']}" for a in arms)
        + ". Checked through what they are for: dyngen's Y pi_full and Pinocchio's regressor times its "
        "dynamic parameters, both against pinocchio::rnea",
        "- parameters: " + "; ".join(f"{a['name']} {a['p_source']}" for a in arms),
        "- agreement checked before timing, on every state (max relative error "
        "|dyngen - Pinocchio| / max(1, |Pinocchio|)): " + "; ".join(
            f"{a['name']} " + ", ".join(f"{f} {errors[(a['name'], f)]:.1e}"
                                        for f in (*FUNCTIONS, "pinocchio_regressor")) for a in arms),
        f"- peak memory of the timing run (all arms, one process): {peak_mib:.1f} MiB"
        + (f" (at the measurement floor {floor_mib:.1f} MiB: the process itself needs at most that)"
           if peak_mib <= floor_mib + 0.5 else ""),
    ]
    casadi_info = [
        f"- CasADi {casadi_version()} (pip `casadi`, the `bench` extra): bench/casadi_side.py writes a plain "
        "recursive Newton-Euler over casadi.SX on the same Pinocchio model (rotation entries within 1e-12 of "
        "0 or +-1 written exact), gravity = rnea(q, 0, 0), M = casadi.jacobian(rnea(q, 0, qdd; no gravity), qdd); "
        "code-generated with cse=True and compiled into the same binary with the same compiler and flags",
        "- CasADi: the body parameters are an input (Pinocchio's 10 per body); CasADi baked: the same with the "
        "parameters substituted as numbers before code generation (what an MPC user does); dyngen reads its "
        "standard parameters s",
        "- sin/cos Ir: the instructions each side spends on sines and cosines. CasADi's code calls libm's sin "
        "and cos: their instructions inside libm (callgrind_annotate, lines of glibc's math sources). dyngen "
        "evaluates both of an angle with its own polynomial sincos (the <M>_SINCOS macro of the header): its "
        "instructions per angle, measured by callgrind on a probe program (same compiler and flags), times the "
        "function's sin/cos count. 'without sin/cos' compares the rest: the arithmetic of the recursion itself",
        "- the pairs compared ('compared with'): rnea (reads the 10N standard parameters) against CasADi with the "
        "parameters as an input; rnea_nominal (the same nominal parameters folded in as exact numbers by dyngen, "
        "pi = K s included) against CasADi baked; gravity and M against the better CasADi variant. 'best CasADi / "
        "dyngen' is the better variant of either kind, for reference: CasADi baked against dyngen's rnea compares "
        "folded-in numbers with parameters read from memory",
        "- agreement with Pinocchio (max relative error): " + "; ".join(
            f"{a['name']} " + ", ".join(f"{v} {f} {errors[(a['name'], f'{v}_{f}')]:.1e}"
                                        for v in ("casadi", "casadi_baked") for f in CASADI_CODE)
            for a in arms),
    ]
    if irs:
        info.append(f"- Ir/call: callgrind instructions of a run with {args.calls} calls of one function minus "
                    "a run with 0 calls (same set-up), divided by the number of calls")
    print()
    print(plain(rows))
    print()
    print(plain(cas_rows))
    print()
    print("\n".join(info))
    if args.output:
        out = Path(args.output)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text("# dyngen generated C vs Pinocchio\n\n"
                       "Written by `python bench/bench_dynamics.py"
                       + (" --callgrind" if args.callgrind else "") + "`.\n\n"
                       + "\n".join(info) + "\n\n" + markdown(rows) + "\n\n"
                       "ratio = Pinocchio ns/call / dyngen ns/call (above 1: the generated C is faster).\n\n"
                       "## dyngen vs CasADi-generated C\n\n" + "\n".join(casadi_info) + "\n\n"
                       + markdown(cas_rows) + "\n")
        log(f"wrote {out}")
        write_json(out.with_suffix(".json"), arms, times, irs, errors, (peak_mib, floor_mib), args)
    log(f"done in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
