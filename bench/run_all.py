#!/usr/bin/env python3
"""The whole benchmark suite in one command; writes BENCHMARKS.md at the top level.

    python bench/run_all.py                         # everything, full size (6-15 minutes)
    python bench/run_all.py --quick                 # smaller runs of everything (a few minutes)
    python bench/run_all.py --parts dynamics scaling --arms lwr panda

Parts, in the order they run (each one is its own script, run as a child process, writing
its table to bench/results/):

    opcounts     bench_opcounts.py     operation counts of every generated function, per arm
    dynamics     bench_dynamics.py     generated C vs Pinocchio: ns/call, ratio, callgrind Ir
    scaling      bench_scaling.py      synthetic arms of 2-12 joints: generation, size, compile, plot
    extraction   bench_extraction.py   dyngen's driver vs SciPy dual_annealing + SLSQP
    diagnosis    bench_diagnosis.py    30 s of 1 kHz data (reported "not available" while that
                                       script does not exist)
    memory       bench_memory.py       peak memory of each step (last: it collects the peaks the
                                       dynamics and scaling parts recorded)
    streaming    bench_streaming.py    identify --ols on 5-60 min recordings (flat memory), and 20
                                       recordings with 1 and 2 workers

BENCHMARKS.md gets every part's table. A part that was not run by this invocation is
included from its last results file and marked as such; a part that failed is reported as
failed (and the command exits non-zero).
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
from common import arguments, cpu_model, log  # noqa: E402  (bench/ is sys.path[0])
RESULTS = BENCH / "results"
PARTS = ("opcounts", "dynamics", "scaling", "extraction", "diagnosis", "memory", "kinematics", "firmware", "streaming")
TITLES = {
    "opcounts": "Operation counts of the generated functions",
    "dynamics": "Generated C vs Pinocchio (time per call, instructions per call)",
    "scaling": "Generation time and code size against the number of joints",
    "extraction": "Extraction: dyngen's driver vs SciPy",
    "diagnosis": "Diagnosis: 30 s of 1 kHz data",
    "memory": "Peak memory of each step",
    "kinematics": "Kinematics and control() vs Pinocchio (time per call, instructions per call)",
    "firmware": "Firmware build: size and stack of every function (Cortex-M4F, Cortex-M7)",
    "streaming": "Hours of data, many recordings",
}
DIAGNOSIS_SCRIPT = BENCH / "bench_diagnosis.py"
# Reading notes for a part's table, where the script's own output can mislead.
# part -> (regular expression that must match its table, note).
NOTES = {
    "extraction": (r"\n\| \w+ \| \d+, 0% \|",
                   "Reading note: bench_extraction.py (owned by the extraction work, called here as it is) divides "
                   "the time per restart by max(success rate, 1e-9): where dyngen's success rate is 0%, its 'time "
                   "to a success' (about 3e8 s) and the ratio mean that none of the restarts succeeded."),
}


@dataclass
class Outcome:
    part: str
    ran: bool = False
    ok: bool = True
    seconds: float = 0.0
    command: str = ""
    note: str = ""
    output_tail: list = field(default_factory=list)


def part_command(part: str, args) -> list | None:
    """The command line of a part (None: nothing to run)."""
    py = [sys.executable]
    arms = ["--arms", *args.arms] if args.arms else []
    if part == "opcounts":
        return [*py, BENCH / "bench_opcounts.py", *arms]
    if part == "dynamics":
        quick = ["--batches", "30"] if args.quick else ["--callgrind", "--native"]
        if not args.quick and not shutil.which("valgrind"):
            log("warning: valgrind is not installed (DYNGEN_BENCH=1 bash scripts/setup.sh): no instruction counts")
            quick = []
        return [*py, BENCH / "bench_dynamics.py", *(arms or (["--arms", "lwr", "stanford"] if args.quick else [])),
                *quick]
    if part == "scaling":
        return [*py, BENCH / "bench_scaling.py", *(["--joints", "2", "4", "6", "7"] if args.quick else [])]
    if part == "extraction":
        quick = ["--arms", "lwr", "--restarts", "8", "--scipy-restarts", "1"] if args.quick else []
        return [*py, BENCH / "bench_extraction.py", *quick]  # its own arms: those with bounds
    if part == "diagnosis":
        return [*py, DIAGNOSIS_SCRIPT] if DIAGNOSIS_SCRIPT.is_file() else None
    if part == "memory":
        return [*py, BENCH / "bench_memory.py"]
    if part == "kinematics":
        quick = ["--batches", "30"] if args.quick or not shutil.which("valgrind") else ["--callgrind"]
        return [*py, BENCH / "bench_kinematics.py", *(arms or (["--arms", "lwr", "stanford"] if args.quick else [])),
                *quick, "--output", RESULTS / "kinematics.md"]
    if part == "firmware":
        return [*py, BENCH / "bench_firmware.py"] if shutil.which("arm-none-eabi-gcc") else None
    if part == "streaming":
        return [*py, BENCH / "bench_streaming.py", *(["--quick", "--repeat", "1"] if args.quick else [])]
    raise ValueError(part)


def run_part(part: str, args) -> Outcome:
    cmd = part_command(part, args)
    out = Outcome(part)
    if cmd is None:
        out.note = ("Not available: arm-none-eabi-gcc is not installed (scripts/setup.sh installs it)"
                    if part == "firmware" else
                    f"Not available: {DIAGNOSIS_SCRIPT.relative_to(ROOT)} does not exist on this branch "
                    "(`dyngen diagnose` is being written on another branch)")
        log(f"== {part}: {out.note}")
        return out
    out.ran = True
    out.command = "python " + " ".join(str(Path(c).relative_to(ROOT)) if str(c).startswith(str(ROOT)) else str(c)
                                       for c in cmd[1:])
    log(f"== {part}: {out.command}")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT / "generator"),
                                                                    os.environ.get("PYTHONPATH")])))
    start = time.perf_counter()
    proc = subprocess.Popen([str(c) for c in cmd], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    tail = []
    for line in proc.stdout:  # stream it: parts take minutes, show they are alive
        sys.stderr.write("   " + line)
        tail = (tail + [line.rstrip("\n")])[-25:]
    proc.wait()
    out.seconds = time.perf_counter() - start
    out.ok = proc.returncode == 0
    out.output_tail = tail
    log(f"== {part}: {'done' if out.ok else f'FAILED ({proc.returncode})'} in {out.seconds:.0f} s")
    return out


# --- BENCHMARKS.md ------------------------------------------------------------------------

def tool_version(cmd: list) -> str:
    if not shutil.which(cmd[0]):
        return "not installed"
    res = subprocess.run(cmd, capture_output=True, text=True)
    return (res.stdout or res.stderr).strip().splitlines()[0] if res.returncode == 0 else "unknown"


def package_version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "not installed"


def environment() -> list:
    cpu = cpu_model()
    try:
        mem = next(line.split()[1] for line in Path("/proc/meminfo").read_text().splitlines()
                   if line.startswith("MemTotal"))
        mem = f", {int(mem) / 1024 ** 2:.1f} GiB RAM"
    except (OSError, StopIteration):
        mem = ""
    try:
        load = "load average at the end %.2f %.2f %.2f" % os.getloadavg()
    except OSError:
        load = ""
    pkgs = ("sympy", "numpy", "scipy", "jinja2", "cffi", "matplotlib", "pin")
    return [
        f"- machine: {os.cpu_count()} cores, {cpu}{mem}, {platform.system()} {platform.release()} "
        f"{platform.machine()}; {load}",
        f"- C / C++ compilers: {tool_version([os.environ.get('CC', 'gcc'), '--version'])}; "
        f"{tool_version([os.environ.get('CXX', 'g++'), '--version'])}",
        f"- valgrind: {tool_version(['valgrind', '--version'])}; NLopt "
        f"{tool_version(['pkg-config', '--modversion', 'nlopt'])} (pkg-config)",
        f"- Python {platform.python_version()}; " + ", ".join(f"{p} {package_version(p)}" for p in pkgs),
    ]


def section_body(part: str) -> str | None:
    """The part's results file without its title, headings demoted, image paths made relative
    to the top level; None if there is no results file."""
    path = RESULTS / f"{part}.md"
    if not path.is_file():
        return None
    lines = path.read_text().splitlines()
    if lines and lines[0].startswith("# "):
        lines = lines[1:]
    text = "\n".join(("#" + line) if line.startswith("#") else line for line in lines).strip()
    return re.sub(r"!\[([^\]]*)\]\((?!/|https?:)([^)]+)\)", r"![\1](bench/results/\2)", text)


def summary() -> list:
    """Headline numbers from the parts' JSON results (whatever exists)."""
    lines = []
    dyn = RESULTS / "dynamics.json"
    if dyn.is_file():
        doc = json.loads(dyn.read_text())
        pairs = next(iter(doc["arms"].values()))["pairs"]
        lines += ["| dyngen vs Pinocchio | time ratio (Pinocchio / dyngen), min - max over arms | "
                  "instruction ratio |", "|---|---:|---:|"]
        for pair in pairs:
            t = [a["pairs"][pair]["pinocchio_ns"] / a["pairs"][pair]["dyngen_ns"] for a in doc["arms"].values()]
            ir = [a["pairs"][pair]["pinocchio_ir"] / a["pairs"][pair]["dyngen_ir"] for a in doc["arms"].values()
                  if a["pairs"][pair]["dyngen_ir"]]
            lines.append(f"| {pair} | {min(t):.2f}x - {max(t):.2f}x | "
                         + (f"{min(ir):.2f}x - {max(ir):.2f}x |" if ir else "not measured |"))
        casadi = [pair for pair in pairs if pairs[pair].get("casadi_ir") is not None]
        if casadi:
            lines += ["", "| dyngen vs CasADi (better of parameters as input / baked in) | time ratio | "
                      "instruction ratio (goal 1.5x) |", "|---|---:|---:|"]
            for pair in casadi:
                t = [min(a["pairs"][pair]["casadi_ns"], a["pairs"][pair]["casadi_baked_ns"])
                     / a["pairs"][pair]["dyngen_ns"] for a in doc["arms"].values()]
                ir = [min(a["pairs"][pair]["casadi_ir"], a["pairs"][pair]["casadi_baked_ir"])
                      / a["pairs"][pair]["dyngen_ir"] for a in doc["arms"].values()]
                lines.append(f"| {pair} | {min(t):.2f}x - {max(t):.2f}x | {min(ir):.2f}x - {max(ir):.2f}x |")
        lines += ["", f"Arms: {', '.join(doc['arms'])}. Above 1: the generated C is faster. yg_pig = Y_g(q) pi_g, "
                  "ym_pim = Y_m(q) pi_m (regressor then product); regressor = dyngen's base regressor vs "
                  "Pinocchio's n x 10n joint-torque regressor.", ""]
    kinematics = RESULTS / "kinematics.json"
    if kinematics.is_file():
        arms = json.loads(kinematics.read_text())
        lines += ["| kinematics and control() vs Pinocchio | time ratio, min - max over arms | instruction ratio |",
                  "|---|---:|---:|"]
        for fn in next(iter(arms.values())):
            t = [a[fn]["pinocchio_ns"] / a[fn]["dyngen_ns"] for a in arms.values()]
            ir = [a[fn]["pinocchio_ir"] / a[fn]["dyngen_ir"] for a in arms.values() if "dyngen_ir" in a[fn]]
            lines.append(f"| {fn} | {min(t):.2f}x - {max(t):.2f}x | "
                         + (f"{min(ir):.2f}x - {max(ir):.2f}x |" if ir else "not measured |"))
        lines += ["", "Pairs and the reading of the control rows: section " + str(PARTS.index("kinematics") + 1) + ".", ""]
    scaling = RESULTS / "scaling.json"
    if scaling.is_file():
        doc = json.loads(scaling.read_text())
        last, k = doc["rows"][-1], doc["exponents"]
        lines.append(f"- Scaling: the {last['n']}-joint synthetic arm generates in {last['generate_s']:.1f} s wall "
                     f"(target < 60 s) and its C compiles in {last['compile_s']:.1f} s wall; growth exponents of cost "
                     f"(target <= 2): generation CPU time {k['generate s']:.2f}, cc CPU time {k['compile s']:.2f}, "
                     f"C size {k['C lines']:.2f} in lines, {k['C bytes']:.2f} in bytes; of run-time multiplications (bound by output size): rnea "
                     f"{k['rnea mul']:.2f}, Y {k['regressor mul']:.2f}, M {k['mass_matrix mul']:.2f}, Y_m "
                     f"{k['regressor_inertia mul']:.2f} (its output has O(n^3) entries).")
    return lines


def write_benchmarks(outcomes: dict, args, total: float) -> Path:
    now = datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    invoked = "python bench/run_all.py" + (" " + " ".join(args.argv) if args.argv else "")
    md = ["# dyngen benchmarks", "",
          f"Written by `{invoked}` on {now} in {total / 60:.1f} min"
          + (" (QUICK run: fewer arms, batches and sizes; no callgrind)" if args.quick else "") + ". "
          "Scripts and methods: [bench/README.md](bench/README.md). Numbers depend on the machine and its load; "
          "callgrind instruction counts do not.", "", *environment(), ""]
    headline = summary()
    if headline:
        md += ["## Summary", "", *headline, ""]
    for i, part in enumerate(PARTS, 1):
        o = outcomes.get(part)
        md += [f"## {i}. {TITLES[part]}", ""]
        if o is not None and not o.ok:
            md += [f"**FAILED** in this run (`{o.command}`, {o.seconds:.0f} s). Last output:", "", "```",
                   *o.output_tail, "```", ""]
            continue
        if o is not None and not o.ran:
            md += [o.note, ""]
            continue
        body = section_body(part)
        if o is not None:
            md.append(f"Run by this command: `{o.command}` ({o.seconds:.0f} s).")
        elif body is not None:
            md.append(f"Not rerun by this command: the last results file, bench/results/{part}.md, as it is.")
        if body is None:
            if o is not None and o.output_tail:  # e.g. a diagnosis script that prints only
                md += ["", "```", *o.output_tail, "```"]
            else:
                md.append("No results yet: run this part.")
        else:
            md += ["", body]
            if part in NOTES and re.search(NOTES[part][0], body):
                md += ["", NOTES[part][1]]
        md.append("")
    path = Path(args.output)
    path.write_text("\n".join(md).rstrip() + "\n")
    return path


def main(argv=None) -> int:
    ap = arguments(__doc__, formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__.split("\n\n", 2)[2])
    ap.add_argument("--parts", nargs="+", choices=PARTS, default=list(PARTS), help="parts to run (default: all)")
    ap.add_argument("--arms", nargs="+", help="example arms for opcounts and dynamics (default: all examples; "
                    "extraction always uses its own list of arms with bounds)")
    ap.add_argument("--quick", action="store_true",
                    help="smaller runs: dynamics on lwr and stanford with 30 batches and no callgrind, scaling up "
                         "to 7 joints, extraction on lwr with 8 restarts and 1 SciPy restart")
    ap.add_argument("--output", default=str(ROOT / "BENCHMARKS.md"), help="report file (default BENCHMARKS.md)")
    args = ap.parse_args(argv)
    args.argv = list(argv if argv is not None else sys.argv[1:])
    RESULTS.mkdir(exist_ok=True)
    start = time.perf_counter()
    outcomes = {}
    for part in PARTS:
        if part in args.parts:
            outcomes[part] = run_part(part, args)
    path = write_benchmarks(outcomes, args, time.perf_counter() - start)
    failed = [p for p, o in outcomes.items() if not o.ok]
    log(f"wrote {path}" + (f"; FAILED parts: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
