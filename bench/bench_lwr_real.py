"""The diagnosis on the real KUKA LWR4+ recordings (examples/lwr4-real), with three roles:
fit on measurement 1, 2 or both (selection on blocks of them), test on measurement 3 (a
different, faster trajectory), and fit 1 -> test 2 (the same trajectory repeated: must be
flagged). Per joint, the test RMS of the nominal model, of the final model, and of the simple
model (offset + Coulomb + viscous per joint, fitted on the same fit data).

    python bench/bench_lwr_real.py        # writes bench/results/lwr_real.md
"""

from __future__ import annotations

import dataclasses
import sys
import time

from common import arguments, on_path  # noqa: E402  (bench/ is sys.path[0])

ROOT = on_path()

from dyngen import blas  # noqa: E402

blas.use_one_thread()

import numpy as np  # noqa: E402

from dyngen.atomic import write_file  # noqa: E402
from dyngen.data import condition, read_recording  # noqa: E402
from dyngen.data.parameters_file import read_link_parameters  # noqa: E402
from dyngen.description import load_robot  # noqa: E402
from dyngen.diagnosis import Options, diagnose  # noqa: E402
from dyngen.runtime import load  # noqa: E402

HERE = ROOT / "examples" / "lwr4-real"
RUNS = (([1], [3]), ([2], [3]), ([1, 2], [3]), ([1], [2]))


def simple_of(d):
    return np.array(d.rms_simple)


def main() -> int:
    arguments(__doc__, whole=True).parse_args()
    robot, model = load_robot(ROOT / "examples" / "lwr.yaml"), load(ROOT / "generated" / "lwr")
    p = read_link_parameters(ROOT / "examples" / "lwr_paper_solution.yaml", 7)

    def recording(k):
        return condition(read_recording(HERE / f"measurement_{k}.csv", 7))

    lines = ["# Diagnosis of the real LWR4+ (bench/bench_lwr_real.py)", "",
             "`python bench/bench_lwr_real.py`: paper's parameters (examples/lwr_paper_solution.yaml), default "
             "options; fit on the named measurement(s) with selection on blocks of them, test on another that "
             "plays no other part. Test RMS per joint [Nm]; 'simple' is b + Fc tanh(qd/0.02) + Fv qd per joint "
             "fitted on the same fit data. The last row: the same with the consistent re-identification of the link "
             "parameters as a per-joint alternative (`--reidentify`, diagnosis/reidentify.py).", ""]
    for fit, test in RUNS:
        start = time.perf_counter()
        d = diagnose(robot, model, p, [recording(k) for k in fit], None, test=[recording(k) for k in test])
        seconds = time.perf_counter() - start
        start = time.perf_counter()
        r = diagnose(robot, model, p, [recording(k) for k in fit], None, Options(reidentify=True),
                     test=[recording(k) for k in test])
        r_seconds = time.perf_counter() - start
        r_after = np.array(r.rms_after)
        r_worse = [j + 1 for j in range(7) if r_after[j] > simple_of(d)[j] + 1e-9]
        after, simple = np.array(d.rms_after), np.array(d.rms_simple)
        worse = [j + 1 for j in range(7) if after[j] > simple[j] + 1e-9]
        name = f"fit m{'+m'.join(map(str, fit))} -> test m{test[0]}"
        lines += [f"## {name} ({seconds:.1f} s)", "",
                  "| | " + " | ".join(f"J{j}" for j in range(1, 8)) + " | mean |", "|---|" + "---:|" * 8,
                  "| nominal | " + " | ".join(f"{x:.3f}" for x in d.rms_before) + f" | {np.mean(d.rms_before):.3f} |",
                  "| **final model** | " + " | ".join(f"{x:.3f}" for x in after) + f" | {after.mean():.3f} |",
                  "| selected effects alone | " + " | ".join(f"{x:.3f}" for x in d.rms_effects)
                  + f" | {np.mean(d.rms_effects):.3f} |",
                  "| simple model | " + " | ".join(f"{x:.3f}" for x in simple) + f" | {simple.mean():.3f} |",
                  f"| final model with `--reidentify` ({r_seconds:.1f} s) | " + " | ".join(f"{x:.3f}" for x in r_after)
                  + f" | {r_after.mean():.3f} |", "",
                  f"With `--reidentify`: worse than the simple model on {r_worse or 'none'}; link parameters off: "
                  f"{r.consistent.joints if r.consistent else 'not claimed'}"
                  + (f" (regularisation {r.consistent.regularisation:g})" if r.consistent else "") + ".", "",
                  within_fit_speeds(d),
                  f"Joints where the final model is worse than the simple model: {worse or 'none'}. Per joint "
                  f"model: {', '.join(f'J{j + 1} {m}' for j, m in enumerate(d.joint_models))}.", "",
                  "Selected: " + "; ".join(f"{e.effect} {list(e.joints)}" for e in d.selected) + ".", ""]
        lines += [f"- warning: {w}" for w in d.warnings] + [""]
        print(f"{name}: after {np.round(after, 3)} mean {after.mean():.3f}; simple {np.round(simple, 3)}; "
              f"worse on {worse}; --reidentify {np.round(r_after, 3)} mean {r_after.mean():.3f} worse on {r_worse}, "
              f"link parameters off {r.consistent.joints if r.consistent else None}", flush=True)
    lines += positions_only(robot, model, p)
    lines += block_lengths(robot, model, p, recording)
    write_file(ROOT / "bench" / "results" / "lwr_real.md", "\n".join(lines))
    return 0


def within_fit_speeds(d) -> str:
    """The table's rows at the joint velocities the fit data covered (Diagnosis.within_fit_speeds)."""
    w = d.within_fit_speeds
    worse = [j + 1 for j, (a, s) in enumerate(zip(w["rms_after"], w["rms_simple"]))
             if a is not None and a > s + 1e-9]
    return ("At the joint velocities the fit data covered (share of test samples beyond them per joint: "
            + ", ".join(f"{x:.0%}" for x in w["share_beyond"]) + "): final model "
            + " ".join("-" if a is None else f"{a:.3f}" for a in w["rms_after"]) + ", simple model "
            + " ".join("-" if a is None else f"{a:.3f}" for a in w["rms_simple"])
            + f"; worse than the simple model on {worse or 'none'}.\n")


def positions_only(robot, model, p) -> list[str]:
    """The same fits and tests with the recordings' qd and qdd columns dropped: the real
    encoder positions alone, differentiated by dyngen's conditioning (cutoff chosen from the data)."""
    def recording(k):
        r = read_recording(HERE / f"measurement_{k}.csv", 7)
        return condition(dataclasses.replace(r, qd=None, qdd=None))

    lines = ["## Positions only (qd and qdd columns dropped)", "",
             "The recordings' velocity and acceleration columns removed: dyngen differentiates the real encoder "
             "positions through the low-pass it chooses from the data. Test RMS on m3 [Nm].", "",
             "| fit -> test | | " + " | ".join(f"J{j}" for j in range(1, 8)) + " | mean |", "|---|---|" + "---:|" * 8]
    for fit, test in RUNS[:3]:
        d = diagnose(robot, model, p, [recording(k) for k in fit], None, test=[recording(k) for k in test])
        after, simple = np.array(d.rms_after), np.array(d.rms_simple)
        worse = [j + 1 for j in range(7) if after[j] > simple[j] + 1e-9]
        name = f"m{'+m'.join(map(str, fit))} -> m{test[0]}"
        cut = ", ".join(f"{c.note}" for c in d.conditioning[:1])
        label = "worse than simple on " + (", ".join(f"J{j}" for j in worse) if worse else "none")
        lines += [f"| {name} | **final model** ({label}) | " + " | ".join(f"{x:.3f}" for x in after)
                  + f" | {after.mean():.3f} |",
                  "| | simple model | " + " | ".join(f"{x:.3f}" for x in simple) + f" | {simple.mean():.3f} |"]
        print(f"positions only, {name}: after {np.round(after, 3)} mean {after.mean():.3f}; simple "
              f"{np.round(simple, 3)}; worse on {worse}; {cut}", flush=True)
    return lines + [""]


BLOCKS = (1.5, 2.0, 2.5, 3.0)  # s: selection block lengths (Options.block_seconds; 2 s the default)


def block_lengths(robot, model, p, recording) -> list[str]:
    """The same fits with other selection block lengths: how much the result owes to one way of
    cutting the fit data into fit and selection blocks."""
    lines = ["## Other selection block lengths (diagnosis Options.block_seconds; 2 s by default)", "",
             "Test RMS on m3 [Nm]: mean over joints; each joint worse than the simple model, with the "
             "simple model's RMS; and the joints worse at the velocities the fit data covered.", "",
             "| fit | " + " | ".join(f"{b:g} s" for b in BLOCKS) + " |", "|---|" + "---|" * len(BLOCKS)]
    for fit, _ in RUNS[:3]:
        cells = []
        for seconds in BLOCKS:
            d = diagnose(robot, model, p, [recording(k) for k in fit], None, Options(block_seconds=seconds),
                         test=[recording(3)])
            after, simple = np.array(d.rms_after), np.array(d.rms_simple)
            worse = [j + 1 for j in range(7) if after[j] > simple[j] + 1e-9]
            w = d.within_fit_speeds
            inside = [j + 1 for j, (a, s) in enumerate(zip(w["rms_after"], w["rms_simple"]))
                      if a is not None and a > s + 1e-9]
            cells.append(f"{after.mean():.3f}" + "".join(f"; J{j} {after[j - 1]:.3f} > {simple[j - 1]:.3f}"
                                                         for j in worse)
                         + f"; within the fit speeds worse on {', '.join(f'J{j}' for j in inside) or 'none'}")
        lines.append(f"| m{'+m'.join(map(str, fit))} | " + " | ".join(cells) + " |")
        print(f"block lengths {BLOCKS}, fit {fit}: {cells}", flush=True)
    return lines + [""]


if __name__ == "__main__":
    sys.exit(main())
