#!/usr/bin/env python3
"""Benchmark: hours of data and many recordings (dyngen.streaming).

1. Peak memory and wall time of `dyngen identify --ols` (least squares accumulated in blocks),
   `dyngen identify` (the consistent identification, its recordings read in blocks on every pass:
   identification/blocks.py) on the real LWR4+ run tiled to 5, 30 and 60 minutes at 200 Hz (CSV), and to 60 minutes at
   1 kHz (Parquet: 3.6 M rows of 7 joints), each in its own child process (peak_memory.py).
   Flat means: the peak does not grow with the length.
2. 20 recordings of 5 minutes (the tiled run, each one from another of the three real runs):
   wall time of `--workers 1` against `--workers 2` (target: at most 0.6x), and the same
   coefficients from both.
   Also `dyngen diagnose` (the full diagnosis on evenly spread windows of at most --max-rows
   samples, the gap and simple model over every sample in blocks: streaming/sample.py) on the
   same files; a figure of the peaks against the length (results/streaming_memory.png).
Writes bench/results/streaming.md and streaming.json.

    python bench/bench_streaming.py [--quick] [--repeat N] [--parts memory parallel] [--lengths 5 30 60 60k]
                                    [--commands identify ...]
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

from common import BENCH, ROOT, arguments, log, machine
from long_recordings import write
from peak_memory import run_measured

RESULTS = BENCH / "results"
REAL = [ROOT / "examples" / "lwr4-real" / f"measurement_{k}.csv" for k in (1, 2, 3)]


def identify(data: list, out: Path, model: Path, workers: int = 1, ols: bool = True):
    cmd = [sys.executable, "-m", "dyngen", "identify", ROOT / "examples" / "lwr.yaml", *(["--ols"] if ols else []),
           "--model", model, "-o", out, "--workers", str(workers)]
    for d in data:
        cmd += ["--data", d]
    m = run_measured(cmd, env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    if m.returncode != 0:
        raise SystemExit(f"failed: {' '.join(map(str, cmd))}\n{m.stderr}")
    return m


def survey(path: Path, tmp: Path, model: Path):
    cmd = [sys.executable, "-m", "dyngen", "diagnose", ROOT / "examples" / "lwr.yaml", "--params",
           ROOT / "examples" / "lwr_paper_solution.yaml", "--survey", "--data", path, "--model", model,
           "--out", tmp / "survey", "-q"]
    m = run_measured(cmd, env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    if m.returncode != 0:
        raise SystemExit(f"failed: {' '.join(map(str, cmd))}\n{m.stderr}")
    return m


def diagnosis(path: Path, tmp: Path, model: Path):
    cmd = [sys.executable, "-m", "dyngen", "diagnose", ROOT / "examples" / "lwr.yaml", "--params",
           ROOT / "examples" / "lwr_paper_solution.yaml", "--data", path, "--model", model, "--out", tmp / "diagnosis"]
    m = run_measured(cmd, env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    if m.returncode != 0:
        raise SystemExit(f"failed: {' '.join(map(str, cmd))}\n{m.stderr}")
    return m


COMMANDS = {"identify --ols": lambda path, tmp, model: identify([path], tmp / "out.yaml", model),
            "identify": lambda path, tmp, model: identify([path], tmp / "consistent" / "out.yaml", model, ols=False),
            "diagnose --survey": survey, "diagnose": diagnosis}


def stage_seconds(m) -> float:
    """The per-recording stage's wall time, from the command's progress line."""
    import re

    found = re.search(r"in blocks done \(([0-9.]+) s\)", m.stdout + m.stderr)
    return float(found.group(1)) if found else float("nan")


def values(path: Path) -> list:
    import re

    return [float(v) for v in re.findall(r"value: (\S+)\}", path.read_text())]


LENGTHS = {"5": (5, None, "csv"), "30": (30, None, "csv"), "60": (60, None, "csv"), "60k": (60, 1000, "parquet")}


def part_memory(tmp, model, lengths, commands, rows_out: list, save) -> None:
    """Each command on each length; a row replaces the last results file's row of the same
    command, length and rate, and the file is saved after every row (a run cut short keeps
    what it measured)."""
    for minutes, rate, suffix in (LENGTHS[k] for k in lengths):
        path = tmp / f"lwr_{minutes}min_{rate or 200}hz.{suffix}"
        rows = write(path, minutes, rate)
        for command in commands:
            log(f"{command} on {path.name} ({rows} rows) ...")
            m = COMMANDS[command](path, tmp, model)
            rows_out[:] = [r for r in rows_out if (r["command"], r["minutes"], r["rate"]) != (command, minutes, rate or 200)]
            rows_out.append({"command": command, "minutes": minutes, "rate": rate or 200, "format": suffix,
                             "rows": rows, "file_mib": path.stat().st_size / 2 ** 20, "seconds": m.seconds,
                             "cpu_seconds": m.cpu_seconds, "peak_mib": m.max_rss_mib})
            rows_out.sort(key=lambda r: (list(COMMANDS).index(r["command"]), r["rate"], r["minutes"]))
            save()
        path.unlink()


def _burn(n: int) -> float:
    x = 0
    for i in range(n):
        x += i * i
    return float(x)


def calibration(repeat: int) -> float:
    """Wall time of 8 pure-Python CPU tasks on 2 worker processes over that on 1 (fastest of
    `repeat`): what this machine allows two processes of this benchmark at this moment (1.0 when
    its scheduler gives them one core's worth in all, e.g. a session's autogroup on a loaded machine)."""
    import time
    from concurrent.futures import ProcessPoolExecutor

    best = {}
    for _ in range(repeat):
        for workers in (1, 2):
            start = time.perf_counter()
            with ProcessPoolExecutor(workers) as pool:
                list(pool.map(_burn, [3_000_000] * 8))
            best[workers] = min(best.get(workers, 1e9), time.perf_counter() - start)
    return best[2] / best[1]


def part_parallel(tmp, model, quick, repeat) -> dict:
    count = 6 if quick else 20
    files = []
    for k in range(count):
        path = tmp / f"robot{k:02d}.csv"
        write(path, 5, None, REAL[k % 3])
        files.append(path)
    runs = {}
    for attempt in range(repeat):  # alternating, so that a change of the machine's load hits both alike
        for workers in (1, 2):
            log(f"{count} recordings, --workers {workers} (run {attempt + 1}) ...")
            m = identify(files, tmp / f"pooled{workers}.yaml", model, workers)
            r = {"seconds": m.seconds, "stage_seconds": stage_seconds(m), "cpu_seconds": m.cpu_seconds,
                 "peak_mib": m.max_rss_mib}
            if str(workers) not in runs or r["seconds"] < runs[str(workers)]["seconds"]:
                runs[str(workers)] = r
    same = max(abs(a - b) / max(abs(b), 1e-12) for a, b in zip(values(tmp / "pooled1.yaml"), values(tmp / "pooled2.yaml")))
    return {"recordings": count, "repeat": repeat, "runs": runs, "largest_relative_difference": same,
            "calibration": calibration(repeat)}


def figure(doc, path: Path) -> None:
    """Peak memory against the recording's length, per command (200 Hz CSV; the 1 kHz hour marked)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    for command in dict.fromkeys(r["command"] for r in doc["memory"]["rows"]):
        rows = [r for r in doc["memory"]["rows"] if r["command"] == command]
        at200 = [r for r in rows if r["rate"] == 200]
        line, = ax.plot([r["minutes"] for r in at200], [r["peak_mib"] for r in at200], "o-", label=command)
        for r in rows:
            if r["rate"] != 200:
                ax.plot([r["minutes"]], [r["peak_mib"]], "s", color=line.get_color(), mfc="none")
    ax.set_xlabel("recording length [min] (squares: 1 kHz, Parquet; dots: 200 Hz, CSV)")
    ax.set_ylabel("peak memory [MiB]")
    ax.set_ylim(0, 1024)
    ax.axhline(1024, color="grey", lw=0.8)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("LWR4+ (7 joints), real run tiled: peak memory against length", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def markdown(doc) -> list:
    md = ["# Hours of data, many recordings", "",
          f"Machine: {doc['machine']}; load average {doc['load'][0]:.1f} at the end of the last part run (other "
          "jobs share the cores: wall times are upper bounds; CPU times are this command's own).", ""]
    if "memory" in doc:
        md += ["`dyngen identify --ols` (least squares accumulated in blocks of 8192 samples into per-joint QR "
               "factors, dyngen.streaming), `dyngen identify` (the consistent identification: beyond --max-rows "
               "the recording is read in blocks on every pass, identification/blocks.py) and `dyngen diagnose --survey` (the gap and the simple model in blocks, "
               "streaming/gap.py) and `dyngen diagnose` (the full diagnosis on evenly spread 6-s windows of at most 24000 "
               "samples, the gap and simple model over every sample in blocks: streaming/sample.py) on the real LWR4+ run (examples/lwr4-real/measurement_1.csv, 25 s at "
               "200 Hz) repeated end to end; the 1 kHz hour resampled by linear interpolation. Peak: the largest "
               "resident set (bench/peak_memory.py) of the whole command (Python, NumPy, the compiled model).", "",
               "| command | length | rate | format | rows | file | wall | CPU | peak memory |",
               "|---|---|---|---|---:|---:|---:|---:|---:|"]
        for r in doc["memory"]["rows"]:
            md.append(f"| {r.get('command', 'identify --ols')} | {r['minutes']} min | {r['rate']} Hz | {r['format']} | {r['rows']} | {r['file_mib']:.0f} MiB "
                      f"| {r['seconds']:.1f} s | {r['cpu_seconds']:.1f} s | {r['peak_mib']:.0f} MiB |")
        md.append("")
    if "parallel" in doc:
        par, runs = doc["parallel"], doc["parallel"]["runs"]
        md += [f"{par['recordings']} recordings of 5 minutes (each a tiled real run), pooled fit and per-recording "
               "table, `--workers 1` and `--workers 2`:", "",
               "| workers | wall, whole command | wall, per-recording stage | CPU | peak memory (largest process) |",
               "|---|---:|---:|---:|---:|"]
        for w, r in runs.items():
            md.append(f"| {w} | {r['seconds']:.1f} s | {r['stage_seconds']:.1f} s | {r['cpu_seconds']:.1f} s | "
                      f"{r['peak_mib']:.0f} MiB |")
        ratio = runs["2"]["seconds"] / runs["1"]["seconds"]
        stage = runs["2"]["stage_seconds"] / runs["1"]["stage_seconds"]
        md += ["", f"Fastest of {par['repeat']} alternating runs each. Wall time with 2 workers: {ratio:.2f}x that of 1 "
               f"for the whole command, {stage:.2f}x for the per-recording stage (target at most 0.6x); coefficients "
               f"equal to {par['largest_relative_difference']:.1e} (largest relative difference). The command "
               "also starts Python and imports dyngen (about 2.5 s of CPU, most of it the consistent "
               "identification's modules that `dyngen identify`'s flags import) and loads the compiled model, in "
               "one process whatever the workers."]
        if "calibration" in par:
            md += ["", f"Calibration at the same time: 8 pure-Python CPU tasks on 2 processes took "
                   f"{par['calibration']:.2f}x the wall time of 1 process (what the machine allowed two processes; "
                   "about 0.5 on an idle 2-core machine)."]
        md.append("")
    return md


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each worker count (the fastest is kept)")
    ap.add_argument("--parts", nargs="+", choices=("memory", "parallel"), default=["memory", "parallel"],
                    help="parts to run; the others are kept from the last results file")
    ap.add_argument("--lengths", nargs="+", choices=tuple(LENGTHS), default=list(LENGTHS),
                    help="memory part: minutes at 200 Hz (CSV), 60k the hour at 1 kHz (Parquet)")
    ap.add_argument("--commands", nargs="+", choices=tuple(COMMANDS), default=list(COMMANDS),
                    help="memory part: the commands to measure")
    args = ap.parse_args(argv)
    tmp = Path(tempfile.mkdtemp(prefix="dyngen-streaming-"))
    log("generating the model ...")
    from dyngen.description import load_robot
    from dyngen.generate import generate

    model = generate(load_robot(ROOT / "examples" / "lwr.yaml"), tmp / "gen").folder
    path = RESULTS / "streaming.json"
    doc = json.loads(path.read_text()) if path.is_file() else {}
    doc = {k: v for k, v in doc.items() if k in ("memory", "parallel")}
    doc.setdefault("memory", {"rows": []})

    def save():
        doc.update(machine=machine(), load=os.getloadavg())
        RESULTS.mkdir(exist_ok=True)
        path.write_text(json.dumps(doc, indent=1) + "\n")
        md = markdown(doc)
        if doc["memory"]["rows"]:
            figure(doc, RESULTS / "streaming_memory.png")
        (RESULTS / "streaming.md").write_text("\n".join(md).rstrip() + "\n")
        return md

    if "memory" in args.parts:
        part_memory(tmp, model, ["5", "30"] if args.quick else args.lengths, args.commands, doc["memory"]["rows"], save)
    if "parallel" in args.parts:
        doc["parallel"] = part_parallel(tmp, model, args.quick, args.repeat)
    print("\n".join(save()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
