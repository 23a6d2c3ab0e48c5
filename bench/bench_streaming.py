#!/usr/bin/env python3
"""Benchmark: hours of data and many recordings (dyngen.streaming).

1. Peak memory and wall time of `dyngen identify --ols` (least squares accumulated in blocks)
   on the real LWR4+ run tiled to 5, 30 and 60 minutes at 200 Hz (CSV), and to 60 minutes at
   1 kHz (Parquet: 3.6 M rows of 7 joints), each in its own child process (peak_memory.py).
   Flat means: the peak does not grow with the length.
2. 20 recordings of 5 minutes (the tiled run, each one from another of the three real runs):
   wall time of `--workers 1` against `--workers 2` (target: at most 0.6x), and the same
   coefficients from both.
Writes bench/results/streaming.md and streaming.json.

    python bench/bench_streaming.py [--quick]      # quick: 5 and 30 min, 6 recordings
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
sys.path.insert(0, str(BENCH))
from common import log, machine  # noqa: E402
from long_recordings import write  # noqa: E402
from peak_memory import run_measured  # noqa: E402

RESULTS = BENCH / "results"
REAL = [ROOT / "examples" / "lwr4-real" / f"measurement_{k}.csv" for k in (1, 2, 3)]


def identify(data: list, out: Path, model: Path, workers: int = 1):
    cmd = [sys.executable, "-m", "dyngen", "identify", ROOT / "examples" / "lwr.yaml", "--ols", "--model", model,
           "-o", out, "--workers", str(workers)]
    for d in data:
        cmd += ["--data", d]
    m = run_measured(cmd, env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    if m.returncode != 0:
        raise SystemExit(f"failed: {' '.join(map(str, cmd))}\n{m.stderr}")
    return m


def stage_seconds(m) -> float:
    """The per-recording stage's wall time, from the command's progress line."""
    import re

    found = re.search(r"in blocks done \(([0-9.]+) s\)", m.stdout + m.stderr)
    return float(found.group(1)) if found else float("nan")


def values(path: Path) -> list:
    import re

    return [float(v) for v in re.findall(r"value: (\S+)\}", path.read_text())]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each worker count (the fastest is kept)")
    args = ap.parse_args(argv)
    tmp = Path(tempfile.mkdtemp(prefix="dyngen-streaming-"))
    log("generating the model ...")
    from dyngen.description import load_robot
    from dyngen.generate import generate

    model = generate(load_robot(ROOT / "examples" / "lwr.yaml"), tmp / "gen").folder
    lengths = [(5, None, "csv"), (30, None, "csv")] + ([] if args.quick else [(60, None, "csv"), (60, 1000, "parquet")])
    memory = []
    for minutes, rate, suffix in lengths:
        path = tmp / f"lwr_{minutes}min_{rate or 200}hz.{suffix}"
        rows = write(path, minutes, rate)
        log(f"identify --ols on {path.name} ({rows} rows) ...")
        m = identify([path], tmp / "out.yaml", model)
        memory.append({"minutes": minutes, "rate": rate or 200, "format": suffix, "rows": rows,
                       "file_mib": path.stat().st_size / 2 ** 20, "seconds": m.seconds, "cpu_seconds": m.cpu_seconds,
                       "peak_mib": m.max_rss_mib})
        path.unlink()
    count = 6 if args.quick else 20
    files = []
    for k in range(count):
        path = tmp / f"robot{k:02d}.csv"
        write(path, 5, None, REAL[k % 3])
        files.append(path)
    runs = {}
    for attempt in range(args.repeat):  # alternating, so that a change of the machine's load hits both alike
        for workers in (1, 2):
            log(f"{count} recordings, --workers {workers} (run {attempt + 1}) ...")
            m = identify(files, tmp / f"pooled{workers}.yaml", model, workers)
            r = {"seconds": m.seconds, "stage_seconds": stage_seconds(m), "cpu_seconds": m.cpu_seconds,
                 "peak_mib": m.max_rss_mib}
            if workers not in runs or r["seconds"] < runs[workers]["seconds"]:
                runs[workers] = r
    same = max(abs(a - b) / max(abs(b), 1e-12) for a, b in zip(values(tmp / "pooled1.yaml"), values(tmp / "pooled2.yaml")))
    load = os.getloadavg()
    doc = {"machine": machine(), "load": load, "memory": memory, "parallel": {"recordings": count, "runs": runs,
                                                                                "largest_relative_difference": same}}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "streaming.json").write_text(json.dumps(doc, indent=1) + "\n")
    ratio = runs[2]["seconds"] / runs[1]["seconds"]
    doc["parallel"]["stage_ratio"] = runs[2]["stage_seconds"] / runs[1]["stage_seconds"]
    (RESULTS / "streaming.json").write_text(json.dumps(doc, indent=1) + "\n")
    md = ["# Hours of data, many recordings", "",
          f"Machine: {machine()}; load average at the end {load[0]:.1f} (other jobs share the cores: wall times "
          "are upper bounds).", "",
          "`dyngen identify --ols` (least squares accumulated in blocks of 8192 samples into per-joint QR factors, "
          "dyngen.streaming) on the real LWR4+ run (examples/lwr4-real/measurement_1.csv, 25 s at 200 Hz) repeated "
          "end to end; the 1 kHz hour resampled by linear interpolation. Peak: the largest resident set "
          "(bench/peak_memory.py), of the whole command (Python, NumPy, the compiled model).", "",
          "| length | rate | format | rows | file | wall | CPU | peak memory |", "|---|---|---|---:|---:|---:|---:|---:|"]
    for r in memory:
        md.append(f"| {r['minutes']} min | {r['rate']} Hz | {r['format']} | {r['rows']} | {r['file_mib']:.0f} MiB | "
                  f"{r['seconds']:.1f} s | {r['cpu_seconds']:.1f} s | {r['peak_mib']:.0f} MiB |")
    md += ["", f"{count} recordings of 5 minutes (each a tiled real run), pooled fit and per-recording table:", "",
           "| workers | wall, whole command | wall, per-recording stage | CPU | peak memory (largest process) |",
          "|---|---:|---:|---:|---:|"]
    for w, r in runs.items():
        md.append(f"| {w} | {r['seconds']:.1f} s | {r['stage_seconds']:.1f} s | {r['cpu_seconds']:.1f} s | "
                  f"{r['peak_mib']:.0f} MiB |")
    stage = runs[2]["stage_seconds"] / runs[1]["stage_seconds"]
    md += ["", f"Fastest of {args.repeat} alternating runs each. Wall time with 2 workers: {ratio:.2f}x that of 1 for "
           f"the whole command, {stage:.2f}x for the per-recording stage (target at most 0.6x); coefficients equal "
           f"to {same:.1e} (largest relative difference). The whole command also starts Python and imports "
           "dyngen (about 2.5 s, most of it the consistent identification's modules that `dyngen identify`'s "
           "flags import) and loads the compiled model, in one process whatever the workers."]
    (RESULTS / "streaming.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
