"""The withheld-effect cases recorded as loggers write them: does the diagnosis give the clean
log's result, or say clearly that the data cannot support one?

    python bench/bench_log_pathologies.py                  # every case, every log
    python bench/bench_log_pathologies.py --cases coulomb,payload --logs 1k-polled,100Hz-17bit

Every case of bench_withheld.py (tests/simulation/withheld_cases.py: CASES, TRACKED_CASES,
COMPOSED_CASES; positions from an encoder, no qd or qdd columns, 0.05 Nm torque noise) is
written cleanly and then through tests/simulation/log_variants.py: at 1 kHz from a 20-bit
encoder with 5.5 % repeated rows, a polling logger (repeated, dropped and late rows at once, as
franka_ros writes), 5 % dropped samples, stamps late by up to 0.4 ms, torques held for ten
samples; at 100 Hz from a 17-bit encoder, clean, with repeated rows and with dropped samples;
and at 1 kHz from a 17-bit encoder. Each runs through `dyngen diagnose`'s function with default
options in both directions (fit on one trajectory, selection on blocks of it, test on the other).

A run is judged as bench_withheld.py judges it (withheld_verdict.problems: exactly the injected
effects, within 20 %, test RMS within 1.5 x the perfect model's), and against its clean log: the
same verdict, or "unusable" (trust.Unusable, exit status 3 of the command). Separately: the
nominal test residual at most the measured torque on every joint carrying torque. Tables to
bench/results/log_pathologies.md (--results).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from common import arguments, on_path  # noqa: E402  (bench/ is sys.path[0])

ROOT = on_path()

from dyngen import blas  # noqa: E402

blas.use_one_thread()

from simulation.log_variants import below_the_torques, variant  # noqa: E402
from simulation.mujoco_measurements import Encoder  # noqa: E402
from simulation.withheld_cases import CASES, COMPOSED_CASES, TRACKED_CASES, write_cases  # noqa: E402
from simulation.withheld_run import DIRECTIONS, run  # noqa: E402

from dyngen.atomic import write_file  # noqa: E402
from dyngen.data import condition, read_recording  # noqa: E402
from dyngen.description import load_robot  # noqa: E402
from dyngen.data.trust import Unusable  # noqa: E402
from dyngen.runtime import load  # noqa: E402

OUT_OF_SCOPE = {"coefficients"}  # not in the default library (bench_withheld.py)
# name -> (rate, encoder, pathology or None for the clean log)
LOGS = {
    "1k-clean": (1000.0, Encoder(), None),
    "1k-repeated": (1000.0, Encoder(), "repeated"),
    "1k-polled": (1000.0, Encoder(), "polled"),
    "1k-dropped": (1000.0, Encoder(), "dropped"),
    "1k-jittered": (1000.0, Encoder(), "jittered"),
    "1k-held": (1000.0, Encoder(), "held"),
    "1k-glitched": (1000.0, Encoder(), "glitched"),
    "100Hz-17bit": (100.0, Encoder(noise=5e-5, bits=17), None),
    "100Hz-17bit-repeated": (100.0, Encoder(noise=5e-5, bits=17), "repeated"),
    "100Hz-17bit-dropped": (100.0, Encoder(noise=5e-5, bits=17), "dropped"),
    "100Hz-17bit-polled": (100.0, Encoder(noise=5e-5, bits=17), "polled"),
    "1k-17bit": (1000.0, Encoder(noise=5e-5, bits=17), None),
}


def one(robot, model, folder, doc, name, direction) -> dict:
    entry = next(c for c in doc["cases"] if c["name"] == name)
    test = condition(read_recording(folder / entry[DIRECTIONS[direction][1]], robot.dof))
    try:
        r = run(robot, model, folder, doc, name, direction)
    except Unusable as err:
        return {"case": name, "direction": direction, "outcome": "unusable", "why": err.line, "below": True,
                "ratio": float("nan"), "seconds": float("nan")}
    r.pop("diagnosis")
    below = below_the_torques(r["before"], test)
    return {"case": name, "direction": direction, "outcome": "pass" if not r["problems"] else "fail",
            "why": "; ".join(r["problems"]), "below": below, "ratio": r["ratio"], "seconds": r["seconds"]}


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("--cases", default="", help="comma-separated case names (default: every case)")
    ap.add_argument("--logs", default=",".join(LOGS), help="comma-separated logs: " + ", ".join(LOGS))
    ap.add_argument("--results", type=Path, default=ROOT / "bench" / "results" / "log_pathologies.md")
    args = ap.parse_args(argv)
    robot, model = load_robot(ROOT / "examples" / "lwr.yaml"), load(ROOT / "generated" / "lwr")
    cases = [c for c in CASES + TRACKED_CASES + COMPOSED_CASES if not args.cases or c.name in args.cases.split(",")]
    logs = [x for x in args.logs.split(",") if x]
    start = time.perf_counter()
    results = {}  # log -> [row]
    with tempfile.TemporaryDirectory(prefix="pathologies-") as tmp:
        written = {}
        for log in logs:
            rate, encoder, pathology = LOGS[log]
            key = (rate, encoder)
            if key not in written:
                folder = Path(tmp) / f"clean-{len(written)}"
                written[key] = (folder, write_cases(folder, rate_hz=rate, cases=cases, encoder=encoder))
            folder, doc = written[key]
            if pathology:
                folder = variant(folder, pathology, Path(tmp) / log)
            rows = results[log] = []
            for case in cases:
                for direction in DIRECTIONS:
                    r = one(robot, model, folder, doc, case.name, direction)
                    rows.append(r)
                    print(f"{log:<22} {case.name:<18} {direction:<9} {r['outcome']:<9} below {r['below']!s:<5} "
                          f"ratio {r['ratio']:.2f} {r['why'][:120]}", flush=True)
    clean = {(lg, r["case"], r["direction"]): r for lg, rows in results.items() for r in rows}
    text = report(results, clean, logs, args, time.perf_counter() - start)
    write_file(args.results, text)
    print(f"table: {args.results}")
    return 0


def _clean_of(log: str) -> str | None:
    rate, encoder, pathology = LOGS[log]
    return next((k for k, (r, e, p) in LOGS.items() if r == rate and e == encoder and p is None), None)


def report(results, by_key, logs, args, seconds) -> str:
    lines = ["# The withheld cases as loggers write them (bench/bench_log_pathologies.py)", "",
             f"`python bench/bench_log_pathologies.py --logs {','.join(logs)}"
             + (f" --cases {args.cases}" if args.cases else "") + f"` ({seconds:.0f} s). Default options of "
             "`dyngen diagnose`; each case in both directions. *pass*: the withheld benchmark's verdict (exactly the "
             "injected effects, within 20 %, test RMS within 1.5 x the perfect model's); *as clean*: the same verdict "
             "as the clean log of the same rate and encoder, or a clear *unusable* (exit status 3); *below*: the "
             "nominal test residual at most the measured torque on every joint carrying torque. The coefficients "
             "case is out of scope (not in the default library) and not counted.", "",
             "| log | pass | unusable | fail | as clean (or unusable) | nominal residual below the torques | "
             "seconds per run |", "|---|---:|---:|---:|---:|---:|---:|"]
    details = []
    for log in logs:
        rows = [r for r in results[log] if r["case"] not in OUT_OF_SCOPE]
        base = _clean_of(log)
        same = [r for r in rows if r["outcome"] == "unusable" or base not in results
                or (r["outcome"] == "pass") == (by_key[(base, r["case"], r["direction"])]["outcome"] == "pass")]
        count = {k: sum(r["outcome"] == k for r in rows) for k in ("pass", "unusable", "fail")}
        times = [r["seconds"] for r in rows if r["seconds"] == r["seconds"]]
        lines.append(f"| {log} | {count['pass']}/{len(rows)} | {count['unusable']} | {count['fail']} | "
                     f"{len(same)}/{len(rows)} | {sum(r['below'] for r in rows)}/{len(rows)} | "
                     f"{(sum(times) / len(times)) if times else float('nan'):.2f} |")
        for r in rows:
            if r["outcome"] != "pass" or not r["below"]:
                details.append(f"| {log} | {r['case']} | {r['direction']} | {r['outcome']} | "
                               f"{'yes' if r['below'] else 'NO'} | {r['why'] or '-'} |")
    if details:
        lines += ["", "Runs that did not pass:", "", "| log | case | fit on | outcome | below the torques | why |",
                  "|---|---|---|---|---|---|", *details]
    # the out-of-scope cases are never counted, but what they claim beside their verdict is listed
    outside = [f"| {log} | {r['case']} | {r['direction']} | {r['why'] or '-'} |" for log in logs
               for r in results[log] if r["case"] in OUT_OF_SCOPE]
    if outside:
        lines += ["", "Out of scope, not counted (the whole verdict):", "", "| log | case | fit on | why |",
                  "|---|---|---|---|", *outside]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
