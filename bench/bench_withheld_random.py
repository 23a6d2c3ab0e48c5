"""The diagnosis on random withheld effects: cases drawn at random, not chosen by hand.

    python bench/bench_withheld_random.py                       # 12 cases at 1 kHz, seed 101
    python bench/bench_withheld_random.py --rate 200 --cases 20 --seed 7
    python bench/bench_withheld_random.py --robot examples/panda.yaml   # another arm

bench/bench_withheld.py runs a fixed list of cases, which the diagnosis was developed on. Here
each case draws one or two effects (Coulomb, viscous, Stribeck beside Coulomb, rotor inertia,
sensor offset, sensor gain, payload, tilt, time shift) with random joints and magnitudes in
the ranges below, and a third of them track their reference in a forward simulation (friction
that sticks). Otherwise as bench_withheld.py: the LWR in MuJoCo (tests/simulation), positions
from a 20-bit encoder with 1e-5 rad noise, no qd or qdd columns, torque noise 0.05 Nm, default
options, both directions (fit on the Fourier excitation, test on Table V, and the reverse), the
same verdict. Table to bench/results/withheld_random.md (--results).

--robot: another arm's YAML (its C generated into a temporary folder): the same draws on its
joints, with a second Fourier excitation in place of Table V, which is the LWR's.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import arguments, on_path  # noqa: E402  (bench/ is sys.path[0])

ROOT = on_path()

from dyngen import blas  # noqa: E402

blas.use_one_thread()

import numpy as np  # noqa: E402
from simulation.mujoco_measurements import Effects, Encoder  # noqa: E402
from simulation.withheld_cases import PAYLOAD, Case, write_cases  # noqa: E402
from simulation.withheld_run import run  # noqa: E402

from dyngen.atomic import write_file  # noqa: E402
from dyngen.description import load_robot  # noqa: E402
from dyngen.runtime import load  # noqa: E402

KINDS = ("coulomb", "viscous", "stribeck", "armature", "offset", "gain", "payload", "tilt", "time_shift")


def draw(kind: str, rng, dof: int = 7) -> dict:
    """Effects(...) keyword values of one effect of this kind (joints 1-based, as Effects)."""
    j = int(rng.integers(1, dof + 1))
    sign = rng.choice([-1.0, 1.0])
    if kind == "coulomb":
        return {"coulomb": {j: round(rng.uniform(0.3, 2.0), 2)}}
    if kind == "viscous":
        return {"viscous": {j: round(rng.uniform(0.2, 1.0), 2)}}
    if kind == "stribeck":  # static friction 0.5-1.5 Coulomb levels above a Coulomb level
        fc = round(rng.uniform(0.4, 1.5), 2)
        return {"coulomb": {j: fc}, "stribeck": {j: (round(fc * rng.uniform(0.5, 1.5), 2),
                                                      round(rng.uniform(0.04, 0.25), 3))}}
    if kind == "armature":
        return {"armature": {j: round(rng.uniform(0.03, 0.3), 3)}}
    if kind == "offset":
        return {"offset": {j: round(sign * rng.uniform(0.2, 1.0), 2)}}
    if kind == "gain":
        return {"gain": {j: round(sign * rng.uniform(0.03, 0.1), 3)}}
    if kind == "payload":  # the benchmark's cylinder, 0.5-3 kg
        payload = PAYLOAD * rng.uniform(0.5, 3.0) / PAYLOAD[0]
        payload[1:4] = PAYLOAD[1:4]
        return {"payload": payload}
    if kind == "tilt":
        a = rng.uniform(0, 2 * np.pi)
        return {"tilt_deg": round(rng.uniform(1.5, 5.0), 2), "tilt_axis": (np.cos(a), np.sin(a), 0.0)}
    return {"time_shift": round(rng.uniform(0.003, 0.02), 4)}


def random_cases(count: int, seed: int, dof: int = 7) -> list[Case]:
    rng = np.random.default_rng(seed)
    cases = []
    for i in range(count):
        kinds = rng.choice(KINDS, int(rng.integers(1, 3)), replace=False)
        merged: dict = {}
        for kind in kinds:
            for key, value in draw(kind, rng, dof).items():
                merged[key] = {**merged[key], **value} if isinstance(value, dict) and key in merged else value
        tracked = bool(rng.random() < 0.3) and "time_shift" not in kinds  # the tracker has no sensor lag
        cases.append(Case(f"random{seed}_{i}", Effects(**merged), tracked=tracked))
    return cases


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("--rate", type=float, default=1000.0, help="sample rate [Hz] (default 1000)")
    ap.add_argument("--cases", type=int, default=12, help="number of random cases (default 12)")
    ap.add_argument("--seed", type=int, default=101, help="draws the cases and the noise (default 101)")
    ap.add_argument("--robot", type=Path, default=ROOT / "examples" / "lwr.yaml",
                    help="the arm's YAML (default examples/lwr.yaml)")
    ap.add_argument("--results", type=Path, default=None,
                    help="default bench/results/withheld_random.md (the LWR) or withheld_random_<robot>.md")
    args = ap.parse_args(argv)

    robot = load_robot(args.robot)
    results = args.results or ROOT / "bench" / "results" / (
        "withheld_random.md" if robot.name == "lwr" else f"withheld_random_{robot.name}.md")
    cases = random_cases(args.cases, args.seed, robot.dof)
    rows, passed, start = [], 0, time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="withheld-random-") as tmp:
        model = load(ROOT / "generated" / "lwr") if robot.name == "lwr" else \
            generated(args.robot, robot.name, Path(tmp) / "c")
        doc = write_cases(Path(tmp), rate_hz=args.rate, seed=args.seed, cases=cases, encoder=Encoder(),
                          robot_path=args.robot)
        for case in cases:
            for direction in ("forward", "backward"):
                r = run(robot, model, Path(tmp), doc, case.name, direction, case=case)
                ok = not r["problems"]
                passed += ok
                simple = float(np.max(np.array(r["simple"]) / np.array(r["perfect"])))
                rows.append(f"| {case.name}{' (tracked)' if case.tracked else ''} | {direction} | {r['truth']} | "
                            f"{r['verdict']} | {r['ratio']:.2f} | {simple:.1f} | "
                            f"{'pass' if ok else 'FAIL: ' + '; '.join(r['problems'])} |")
                print(rows[-1], flush=True)
    total = 2 * len(cases)
    text = "\n".join([
        "# Diagnosis on random withheld effects (bench/bench_withheld_random.py)", "",
        f"`python bench/bench_withheld_random.py --rate {args.rate:g} --cases {args.cases} --seed {args.seed}"
        + ("" if robot.name == "lwr" else f" --robot {args.robot}") + "` "
        f"({time.perf_counter() - start:.0f} s). Arm: {robot.name}. Effects drawn at random (one or two per case, random joints and "
        "magnitudes; see the script), encoder positions, default options, both directions; the verdict of "
        "bench_withheld.py. 'after / perfect': the worst joint's test RMS after the diagnosis over what the perfect "
        "model leaves on the same conditioned data; 'simple / perfect': the same for the simple model (offset + "
        "Coulomb + viscous per joint).", "",
        f"**{passed} of {total} runs pass.**", "",
        "| case | fit -> test | truth | verdict (fitted) | after / perfect | simple / perfect | result |",
        "|---|---|---|---|---:|---:|---|", *rows, ""])
    write_file(results, text)
    print(f"{passed} of {total} runs pass; table: {results}")
    return 0


def generated(yaml_path: Path, name: str, out: Path):
    """The arm's C, generated by dyngen's command line into `out`, compiled and loaded."""
    subprocess.run([sys.executable, "-m", "dyngen", "generate", str(yaml_path), "-o", str(out), "-q"], check=True,
                   cwd=ROOT)
    return load(out / name)


if __name__ == "__main__":
    raise SystemExit(main())
