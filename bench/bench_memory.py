#!/usr/bin/env python3
"""Benchmark: peak memory (and wall time) of each step of the pipeline, each measured in its
own child process (bench/peak_memory.py: the maximum resident set size the kernel reports
for the child and the descendants it waited for).

Measured here, for one arm (default the LWR):
    generation     bench_generate.py's worker: load + derive + reduce + emit + write (fresh process)
    C compile      `cc -O2 -c` of each emitted .c file (the largest peak and the total time)
    extraction     `dyngen extract ROBOT.yaml` with an empty driver cache (so it includes
                   compiling the C++ driver with g++), then again with the cached driver.
                   The command generates first, so its peak is at least the generation's.
Collected from the other benchmarks' JSON results when present (not rerun here):
    the dynamics benchmark's timing run (bench/results/dynamics.json) and the generation and
    compile peaks of the largest synthetic arm (bench/results/scaling.json).
Writes bench/results/memory.md.

    python bench/bench_memory.py [--arm lwr]
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
from common import arguments, log, table  # noqa: E402  (bench/ is sys.path[0])

from peak_memory import run_measured  # noqa: E402


def checked(res, what: str):
    if res.returncode != 0:
        raise SystemExit(f"{what} failed ({res.returncode}):\n{res.stdout}{res.stderr}")
    return res


def peak_text(m) -> str:
    """The peak in MiB; at the launcher's floor it only bounds the step from above."""
    return f"{m.max_rss_mib:.0f}" if m.max_rss_kib > m.floor_kib + 512 else f"<= {m.max_rss_mib:.0f} (floor)"


def measure(yaml_path: Path, tmp: Path) -> list:
    """[(step, detail, seconds, peak MiB text)] of the steps measured here."""
    rows = []
    log("generation ...")
    gen = checked(run_measured([sys.executable, BENCH / "bench_generate.py", "--worker", yaml_path, tmp / "gen"]),
                  "generation")
    folder = Path(json.loads(gen.stdout.strip().splitlines()[-1])["folder"])
    rows.append(("generation", f"{yaml_path.name}: load, derive, reduce, emit, write", gen.seconds, peak_text(gen)))

    log("C compile ...")
    cc = os.environ.get("CC", "cc")
    compiles = {src.name: checked(run_measured([cc, "-O2", "-c", src, "-o", src.with_suffix(".o")]), f"cc {src.name}")
                for src in sorted(folder.glob("*.c"))}
    largest = max(compiles, key=lambda f: compiles[f].max_rss_mib)
    rows.append(("C compile", f"`{cc} -O2 -c` of {len(compiles)} .c files, one after another; peak: {largest}",
                 sum(c.seconds for c in compiles.values()), peak_text(compiles[largest])))

    env = dict(os.environ, DYNGEN_CACHE_DIR=str(tmp / "cache"))  # an empty cache: the first run compiles the driver
    (tmp / "drivers").mkdir()
    cmd = [sys.executable, "-m", "dyngen", "extract", yaml_path, "-o", tmp / "gen2", "--out", tmp / "out", "-q"]
    for label in ("static driver and arm compiled (g++) in the run", "driver cached"):
        log(f"extraction ({label}) ...")
        ext = checked(run_measured(cmd, env=env), "dyngen extract")
        rows.append(("extraction", f"`dyngen extract {yaml_path.name}` (generates first), {label}",
                     ext.seconds, peak_text(ext)))
    return rows


def collected() -> list:
    """Peaks recorded by the other benchmarks' last runs."""
    rows = []
    dyn = BENCH / "results" / "dynamics.json"
    if dyn.is_file():
        doc = json.loads(dyn.read_text())
        peak, floor = doc["peak_rss_mib"], doc.get("peak_rss_floor_mib", 0.0)
        rows.append(("dynamics benchmark run", f"the timing process of bench_dynamics.py ({', '.join(doc['arms'])}; "
                     "the Pinocchio side compiled before, cached)", None,
                     f"{peak:.0f}" if peak > floor + 0.5 else f"<= {peak:.0f} (floor)"))
    scaling = BENCH / "results" / "scaling.json"
    if scaling.is_file():
        last = json.loads(scaling.read_text())["rows"][-1]
        rows.append(("generation", f"synthetic {last['n']}-joint arm (bench_scaling.py)", last["generate_s"],
                     f"{last['generate_peak_mib']:.0f}"))
        rows.append(("C compile", f"synthetic {last['n']}-joint arm, `cc -O2 -c` of each file, slowest "
                     f"{last['compile_slowest']} (bench_scaling.py)", last["compile_s"],
                     f"{last['compile_peak_mib']:.0f}"))
    return rows


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("--arm", default="lwr", help="example name (examples/NAME.yaml) or YAML path (default lwr)")
    ap.add_argument("--output", default=str(BENCH / "results" / "memory.md"),
                    help="markdown results (default bench/results/memory.md); '' to skip")
    args = ap.parse_args(argv)
    yaml_path = Path(args.arm) if args.arm.endswith((".yaml", ".yml")) else ROOT / "examples" / f"{args.arm}.yaml"
    if not yaml_path.is_file():
        raise SystemExit(f"no such arm: {args.arm} ({yaml_path})")
    with tempfile.TemporaryDirectory(prefix="dyngen-bench-memory-") as tmp:
        rows = measure(yaml_path.resolve(), Path(tmp))
    extra = collected()
    measured_here = len(rows)
    rows += extra
    lines = ["# Peak memory of each step", "",
             "Written by `python bench/bench_memory.py`. Each step runs in its own child process; peak = the "
             "maximum resident set size of that process or of any process it waited for (wait4's ru_maxrss), "
             "not a sum over processes running at once. Commands are spawned from a minimal launcher "
             "(bench/peak_memory.py) whose own peak, about 10 MiB, is the floor: '<= N (floor)' means the step "
             "needs at most that. Rows marked (collected) come from the last run of "
             "bench_dynamics.py / bench_scaling.py.", "",
             *table(["step", "what", "wall s", "peak MiB"], "llrr")]
    for i, (step, what, seconds, peak) in enumerate(rows):
        tag = "" if i < measured_here else " (collected)"
        lines.append(f"| {step}{tag} | {what} | {'' if seconds is None else f'{seconds:.2f}'} | {peak} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.output:
        Path(args.output).write_text(text)
        log(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
