#!/usr/bin/env python3
"""Benchmark: how long dyngen takes to generate each example arm, and how long the emitted
C takes to compile.

Per arm, each repetition in a fresh Python process (so no arm profits from the symbolic
caches of another, as with the `dyngen` command):
    load     dyngen.description.load_robot (YAML -> Robot)
    derive   symbolic Newton-Euler: the three regressors and rnea / gravity / mass matrix
    reduce   exact rank reduction to the base coefficients
    emit     rendering the C, header, manifest (dyngen.generate.build, in memory)
    (derive/reduce/emit are build()'s own progress steps, timed by a recording Progress)
then the files are written to a temporary folder and every emitted .c file is compiled
there with `cc -O2 -c` (one file after another; wall time of the compiler processes).
Reported: medians over --repeat repetitions. Table: bench/results/generate.md.

    python bench/bench_generate.py [--arms lwr panda ...] [--repeat 3]
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
from common import arguments, arm_yaml, compiler_version, example_arms, log, machine, table  # noqa: E402  (bench/ is sys.path[0])
STAGES = ("load", "derive", "reduce", "emit")


# --- worker: one generation in this (fresh) process ------------------------------------

def worker(yaml_path: str, out_dir: str) -> None:
    from dyngen.atomic import write_folder
    from dyngen.description import load_robot
    from dyngen.generate import build
    from dyngen.progress import Progress

    class Recorder(Progress):
        """Progress that records how long each of build()'s steps takes (wall and CPU
        seconds of this process; CPU time is what other processes' load changes least)."""

        def __init__(self):
            super().__init__(quiet=True)
            self.steps = []

        @contextmanager
        def step(self, what: str):
            start, cpu = time.perf_counter(), time.process_time()
            yield
            self.steps.append((what, time.perf_counter() - start, time.process_time() - cpu))

    t0, c0 = time.perf_counter(), time.process_time()
    robot = load_robot(yaml_path)
    t1, c1 = time.perf_counter(), time.process_time()
    recorder = Recorder()
    _, emitted = build(robot, recorder)
    t2, c2 = time.perf_counter(), time.process_time()
    folder = Path(out_dir) / robot.name
    write_folder(folder, emitted.files)
    times, cpu_times = {"load": t1 - t0, "build": t2 - t1}, {"load": c1 - c0, "build": c2 - c1}
    for what, seconds, cpu_seconds in recorder.steps:
        key = what.split()[0]  # "derive regressors ...", "reduce to ...", "emit C"
        times[key] = times.get(key, 0.0) + seconds
        cpu_times[key] = cpu_times.get(key, 0.0) + cpu_seconds
    print(json.dumps({"name": robot.name, "dof": robot.dof, "folder": str(folder), "times": times,
                      "cpu_times": cpu_times, "steps": recorder.steps}))


def generate_once(yaml_path: Path, out_dir: Path) -> dict:
    res = subprocess.run([sys.executable, __file__, "--worker", str(yaml_path), str(out_dir)],
                         capture_output=True, text=True)
    if res.returncode != 0:
        raise SystemExit(f"generating {yaml_path.name} failed:\n{res.stdout}{res.stderr}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def compile_once(cc: str, flags: list, folder: Path) -> tuple[float, dict]:
    """Wall seconds of `cc FLAGS -c file.c` for every .c in folder, one after another."""
    per_file = {}
    for src in sorted(folder.glob("*.c")):
        start = time.perf_counter()
        res = subprocess.run([cc, *flags, "-c", str(src), "-o", str(src.with_suffix(".o"))],
                             capture_output=True, text=True)
        per_file[src.name] = time.perf_counter() - start
        if res.returncode != 0:
            raise SystemExit(f"{cc} failed on {src}:\n{res.stderr}")
    return sum(per_file.values()), per_file


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("--arms", nargs="+", help="example names or YAML paths; default: all examples")
    ap.add_argument("--repeat", type=int, default=3, help="repetitions per arm, medians reported (default 3)")
    ap.add_argument("--flags", default="-O2", help="C compiler flags (default: -O2)")
    ap.add_argument("--output", default=str(BENCH / "results" / "generate.md"),
                    help="markdown results file (default bench/results/generate.md); '' to skip")
    ap.add_argument("--worker", nargs=2, metavar=("YAML", "DIR"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(*args.worker)
        return 0

    import dyngen

    cc = os.environ.get("CC", "cc")
    flags = shlex.split(args.flags)
    names = args.arms or example_arms()
    rows = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="dyngen-bench-gen-") as tmp:
        for name in names:
            yaml_path = arm_yaml(name)
            runs, compiles, per_file = [], [], {}
            for r in range(args.repeat):
                log(f"{name}: generation {r + 1}/{args.repeat} ...")
                out = Path(tmp) / f"{name}.{r}"
                info = generate_once(yaml_path, out)
                runs.append(info)
                total, files = compile_once(cc, flags, Path(info["folder"]))
                compiles.append(total)
                for f, s in files.items():
                    per_file.setdefault(f, []).append(s)
            folder = Path(runs[0]["folder"])
            lines = sum(len(p.read_text().splitlines()) for p in folder.glob("*.c"))
            med = {k: statistics.median(r["times"].get(k, 0.0) for r in runs) for k in (*STAGES, "build")}
            largest = max(per_file, key=lambda f: statistics.median(per_file[f]))
            rows.append([runs[0]["name"], str(runs[0]["dof"]),
                         *(f"{med[k]:.2f}" for k in STAGES), f"{med['load'] + med['build']:.2f}",
                         f"{len(per_file)} / {lines}", f"{statistics.median(compiles):.2f}",
                         f"{statistics.median(per_file[largest]):.2f} ({largest})"])
    head = ["arm", "dof", "load s", "derive s", "reduce s", "emit s", "generate s",
            ".c files / lines", f"cc {args.flags} s", "slowest .c s"]
    printed = [head, *rows]
    widths = [max(len(r[i]) for r in printed) for i in range(len(head))]
    print()
    print("\n".join("  ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths)))
                    for r in printed))
    info = [
        f"- machine: {machine()}",
        f"- dyngen {dyngen.__version__}, Python {platform.python_version()}; each generation in a fresh "
        "process (imports not counted); generate = load + dyngen.generate.build (derive + reduce + emit, "
        "in memory; writing the files is not counted)",
        f"- C compiler: `{cc}` ({compiler_version(cc)}), `{cc} {args.flags} -c FILE.c` for every emitted .c file, "
        "one after another (cc s = the sum of their wall times)",
        f"- medians over {args.repeat} repetitions",
    ]
    print()
    print("\n".join(info))
    if args.output:
        md = table(head, "l" + "r" * (len(head) - 1), rows)
        out = Path(args.output)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text("# dyngen generation and compile times\n\nWritten by `python bench/bench_generate.py`.\n\n"
                       + "\n".join(info) + "\n\n" + "\n".join(md) + "\n")
        log(f"wrote {out}")
    log(f"done in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
