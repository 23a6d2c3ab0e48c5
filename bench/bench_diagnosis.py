"""Diagnosis speed: 30 s of 1 kHz data on the 7-joint LWR (the issue's target: under 3 s).

Synthetic "measured" data: the generated Newton-Euler with the paper's parameters along two
finite Fourier trajectories (fit and test, 30 s each at 1 kHz), plus Coulomb and viscous
friction on joint 2, a sensor offset on joint 5 and white noise (0.02 Nm). Timed: the whole
diagnosis (residual, every candidate's columns, moments, forward selection, pruning, final
fit, simple model) from conditioned signals; separately, reading and conditioning the CSV files and
writing the outputs (report, JSON, two PNG figures). Also a baseline: the same residual
computed with per-sample cffi calls instead of the batch path.

BLAS threads: dyngen asks for one (its matrices have tens of columns). With OpenBLAS's
default threads on this loaded 2-core machine, the same diagnosis took 17 s instead of about
1 s (the Gram matrices A^T A of 30000 x 64 blocks: 1.1 s each instead of 0.015 s).

    python bench/bench_diagnosis.py          # writes bench/results/diagnosis.md
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from common import arguments, on_path, table  # noqa: E402  (bench/ is sys.path[0])

ROOT = on_path()

from dyngen import blas  # noqa: E402

blas.use_one_thread()  # as the dyngen command does, before numpy loads

import numpy as np  # noqa: E402

from dyngen.data import Conditioning, condition, read_recording  # noqa: E402
from dyngen.data.parameters_file import read_link_parameters  # noqa: E402
from dyngen.description import load_robot  # noqa: E402
from dyngen.diagnosis import diagnose  # noqa: E402
from dyngen.diagnosis.diagnosis_files import write_outputs  # noqa: E402
from dyngen.runtime import load  # noqa: E402

RATE, DURATION, NOISE = 1000.0, 30.0, 0.02


def trajectory(seed):
    rng = np.random.default_rng(seed)
    t = np.arange(0, DURATION, 1 / RATE)
    w = 2 * np.pi * 0.1 * np.arange(1, 5)
    a, b = rng.uniform(-0.4, 0.4, (2, 4, 7)) / np.arange(1, 5)[:, None]
    s, c = np.sin(np.outer(t, w))[:, :, None], np.cos(np.outer(t, w))[:, :, None]
    q = rng.uniform(-0.5, 0.5, 7) + (a * s + b * c).sum(1)
    qd = (w[None, :, None] * (a * c - b * s)).sum(1)
    qdd = (-(w ** 2)[None, :, None] * (a * s + b * c)).sum(1)
    return t, q, qd, qdd


def write_csv(path, t, q, qd, qdd, tau):
    header = ",".join(["t"] + [f"{k}{j}" for k in ("q", "qd", "qdd", "tau") for j in range(1, 8)])
    np.savetxt(path, np.column_stack([t, q, qd, qdd, tau]), delimiter=",", header=header, comments="", fmt="%.9g")


def write_encoder_csv(path, t, q, tau, seed):
    """Positions as a 20-bit encoder with 1e-5 rad noise gives them; no qd, qdd columns."""
    step = 2 * np.pi / 2 ** 20
    q = np.round((q + 1e-5 * np.random.default_rng(seed).standard_normal(q.shape)) / step) * step
    header = ",".join(["t"] + [f"{k}{j}" for k in ("q", "tau") for j in range(1, 8)])
    np.savetxt(path, np.column_stack([t, q, tau]), delimiter=",", header=header, comments="", fmt="%.12g")


def timed(robot, model, p, fit, test):
    diagnose(robot, model, p, [fit], None, test=[test])  # warm-up (imports, first allocations)
    runs, d = [], None
    for _ in range(3):
        start = time.perf_counter()
        d = diagnose(robot, model, p, [fit], None, test=[test])
        runs.append(time.perf_counter() - start)
    return runs, d


def main():
    arguments(__doc__, whole=True).parse_args()
    robot = load_robot(ROOT / "examples" / "lwr.yaml")
    model = load(ROOT / "generated" / "lwr")
    p = read_link_parameters(ROOT / "examples" / "lwr_paper_solution.yaml", 7)
    s = model("standard_from_dynamic", p)
    tmp = Path(tempfile.mkdtemp(prefix="bench-diagnosis-"))
    files, encoder_files = [], []
    for k, seed in enumerate((1, 2)):
        t, q, qd, qdd = trajectory(seed)
        tau = model.batch("rnea", q, qd, qdd, s)
        tau[:, 1] += 0.8 * np.sign(qd[:, 1]) + 0.4 * qd[:, 1]
        tau[:, 4] += -0.5
        tau += np.random.default_rng(10 + k).normal(0, NOISE, tau.shape)
        files.append(tmp / f"run{k}.csv")
        write_csv(files[-1], t, q, qd, qdd, tau)
        encoder_files.append(tmp / f"encoder{k}.csv")
        write_encoder_csv(encoder_files[-1], t, q, tau, 20 + k)

    start = time.perf_counter()
    fit, held = (condition(read_recording(f, 7), Conditioning()) for f in files)
    read_time = time.perf_counter() - start
    runs, d = timed(robot, model, p, fit, held)
    start = time.perf_counter()
    efit, eheld = (condition(read_recording(f, 7), Conditioning()) for f in encoder_files)
    encoder_read_time = time.perf_counter() - start
    encoder_runs, ed = timed(robot, model, p, efit, eheld)
    start = time.perf_counter()
    write_outputs(d, robot, p, tmp / "out", {"params": "paper", "fit": ["run0.csv"], "test": ["run1.csv"],
                                             "conditioning": "as recorded"}, 0.002)
    output_time = time.perf_counter() - start

    start = time.perf_counter()
    batch = model.batch("rnea", fit.q, fit.qd, fit.qdd, s)
    batch_time = time.perf_counter() - start
    start = time.perf_counter()
    single = np.array([model("rnea", a, b, c, s) for a, b, c in zip(fit.q, fit.qd, fit.qdd)])
    single_time = time.perf_counter() - start
    assert np.allclose(batch, single, rtol=0, atol=1e-12)

    claims = ", ".join(f"{e.effect} joint(s) {list(e.joints)}" for e in d.selected)
    encoder_claims = ", ".join(f"{e.effect} joint(s) {list(e.joints)}" for e in ed.selected)
    samples = fit.t.size
    lines = [
        "# Diagnosis speed (bench/bench_diagnosis.py)", "",
        f"LWR (7 joints), paper's parameters; a fit and a test recording of {DURATION:g} s at {RATE:g} Hz "
        f"({samples} samples each; selection on blocks of the fit recording); friction on joint 2, offset on "
        f"joint 5, white noise {NOISE} Nm; {len(d.candidates)} candidate effects tried (Stribeck only beside its "
        f"joint's Coulomb term). Twice: with exact qd, qdd "
        "columns (no filter), and with positions from a 20-bit encoder with 1e-5 rad noise and no qd, qdd "
        f"(cutoff chosen from the data: {efit.cutoff:.3g} Hz; every effect column filtered like the torque).", "",
        *table(["step", "time [s]"], "lr"),
        f"| diagnosis, fit + select + test (residual, columns, moments, selection, refinement, pruning, final "
        f"fit, simple model, per joint choice), recorded qd, qdd, best of 3 | {min(runs):.2f} |",
        f"| the same, all three runs | {', '.join(f'{x:.2f}' for x in runs)} |",
        f"| diagnosis, encoder positions (filtered columns), best of 3 | {min(encoder_runs):.2f} |",
        f"| the same, all three runs | {', '.join(f'{x:.2f}' for x in encoder_runs)} |",
        f"| read and check the two CSV files (recorded qd, qdd) | {read_time:.2f} |",
        f"| read, check and condition the two encoder CSV files (cutoff chosen, filtered) | {encoder_read_time:.2f} |",
        f"| write report, JSON, effects YAML and two PNG figures | {output_time:.2f} |",
        f"| residual rnea for {samples} samples: batch C loop | {batch_time:.4f} |",
        f"| the same with one cffi call per sample | {single_time:.4f} ({single_time / batch_time:.0f}x slower) |",
        "", f"Selected: {claims}.",
        f"Test RMS per joint before: {', '.join(f'{x:.3f}' for x in d.rms_before)}; "
        f"after: {', '.join(f'{x:.3f}' for x in d.rms_after)}; simple model "
        f"{', '.join(f'{x:.3f}' for x in d.rms_simple)}.",
        f"Encoder positions: selected {encoder_claims}; "
        f"test RMS after {', '.join(f'{x:.3f}' for x in ed.rms_after)}.", "",
        "Target: diagnosis of 30 s at 1 kHz on 7 joints under 3 s.", ""]
    out = ROOT / "bench" / "results" / "diagnosis.md"
    out.write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
