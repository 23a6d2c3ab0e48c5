#!/usr/bin/env python3
"""Where a command's memory goes: runs a dyngen command in this process while a thread samples
the resident set size (/proc/self/statm) every 20 ms together with the main thread's stack, and
prints, per stage (the dyngen function on the stack just below the command's top-level
function, with the innermost dyngen function), the largest RSS seen while it ran and by how much
the RSS grew over it.

    python bench/memory_stages.py [--depth 2] diagnose examples/lwr.yaml --params P.yaml --data long.csv [...]

A profile, not a benchmark: sampling misses peaks shorter than the period, and Python's
allocator keeps freed memory, so a stage's "peak" can be an earlier stage's leftovers; the
growth column is what the stage added.
"""
from __future__ import annotations

import os
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGE = os.sysconf("SC_PAGE_SIZE")
TOP = {"diagnose": "diagnosis/run.py", "identify_consistent": "identification/consistent.py"}


def rss_mib() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * PAGE / 2 ** 20


def stage_of(frame, depth: int = 1) -> tuple[str, str]:
    """(stage: the `depth` functions called below the top-level one, innermost dyngen function)."""
    chain = []
    while frame is not None:
        if "/dyngen/" in frame.f_code.co_filename:
            name = frame.f_code.co_filename.split("/dyngen/")[-1]
            chain.append((name, frame.f_code.co_name, frame.f_lineno))
        frame = frame.f_back
    chain.reverse()  # outermost first
    inner = f"{chain[-1][0]}:{chain[-1][1]}:{chain[-1][2]}" if chain else "-"
    for k, (name, function, line) in enumerate(chain):
        if function in TOP and name == TOP[function]:
            below = chain[k + 1:k + 1 + depth]
            if not below:
                return f"{function} line {line}", inner
            return " > ".join([function] + [f"{b[0]}:{b[1]}" for b in below]), inner
    return (chain[1][1] if len(chain) > 1 else "command"), inner


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] in (["-h"], ["--help"]):
        print("usage: memory_stages.py [--depth K] [--trace] COMMAND [ARGS ...]\n\n" + __doc__)
        return 0
    depth, trace = 1, False
    while argv[:1] in (["--depth"], ["--trace"]):
        if argv[0] == "--trace":  # also: the allocation sites that hold the most at the traced peak
            trace, argv = True, argv[1:]
        else:
            depth, argv = int(argv[1]), argv[2:]
    if trace:
        import tracemalloc

        tracemalloc.start(8)
    best = {"size": 0, "snapshot": None}
    from dyngen import blas

    blas.use_one_thread()
    from dyngen.cli import main as dyngen

    main_thread = threading.main_thread().ident
    samples, done = [], threading.Event()

    def sample():
        while not done.is_set():
            frame = sys._current_frames().get(main_thread)
            samples.append((time.perf_counter(), rss_mib(), *stage_of(frame, depth)))
            if trace:
                size = tracemalloc.get_traced_memory()[0]
                if size > 1.1 * best["size"]:  # a snapshot costs time: only on a new peak by 10 %
                    best["size"], best["snapshot"] = size, tracemalloc.take_snapshot()
            done.wait(0.02)

    thread = threading.Thread(target=sample, daemon=True)
    start = time.perf_counter()
    thread.start()
    code = dyngen(argv)
    done.set()
    thread.join()
    stages, order = {}, []
    last = samples[0][1] if samples else 0.0
    for t, rss, stage, inner in samples:
        key = stage
        if key not in stages:
            stages[key] = {"first": t - start, "peak": rss, "grew": 0.0, "seconds": 0.0, "inner": {}}
            order.append(key)
        s = stages[key]
        s["peak"] = max(s["peak"], rss)
        s["grew"] += max(rss - last, 0.0)
        s["seconds"] += 0.02
        s["inner"][inner] = max(s["inner"].get(inner, 0.0), rss)
        last = rss
    print(f"exit {code}; peak RSS {max(r for _, r, _, _ in samples):.0f} MiB over {time.perf_counter() - start:.1f} s",
          file=sys.stderr)
    print("| stage | from | time | peak RSS | RSS added | innermost at its peak |")
    print("|---|---:|---:|---:|---:|---|")
    for key in order:
        s = stages[key]
        inner = max(s["inner"], key=s["inner"].get)
        print(f"| {key} | {s['first']:.1f} s | {s['seconds']:.1f} s | {s['peak']:.0f} MiB | {s['grew']:.0f} MiB | "
              f"{inner} |")
    if trace and best["snapshot"] is not None:
        print(f"\nAt the traced peak ({best['size'] / 2 ** 20:.0f} MiB traced), the allocation sites that held most:\n")
        print("| MiB | blocks | where (innermost dyngen frames) |")
        print("|---:|---:|---|")
        stats = best["snapshot"].statistics("traceback")
        for stat in stats[:12]:
            frames = [f"{f.filename.split('/dyngen/')[-1]}:{f.lineno}" for f in stat.traceback if "/dyngen/" in f.filename]
            print(f"| {stat.size / 2 ** 20:.0f} | {stat.count} | {' < '.join(frames[-3:][::-1]) or stat.traceback[0]} |")
    return code


if __name__ == "__main__":
    sys.exit(main())
