"""Write the withheld-effects case folder (the diagnosis benchmark's "measured" data) and measure it.

    python bench/withheld_cases.py --out /tmp/withheld              # 1 kHz, about 300 MB
    python bench/withheld_cases.py --out /tmp/withheld --rate 200   # the real LWR data's rate

The cases are tests/simulation/withheld_cases.py's CASES, simulated in MuJoCo
(tests/simulation/mujoco_measurements.py); see bench/README.md. After writing, the script reads
every CSV back and reports, per case, the residual of the nominal model (params.yaml through
the generated rnea of generated/lwr) on the fit and the held-out trajectory: the RMS per joint
that a diagnosis starts from, and its ratio to the noise sigma. Table to
bench/results/withheld_cases.md (--results).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from common import arguments, on_path  # noqa: E402  (bench/ is sys.path[0])

ROOT = on_path()

from simulation.mujoco_measurements import read_csv  # noqa: E402
from simulation.withheld_cases import write_cases  # noqa: E402

from dyngen.atomic import write_file  # noqa: E402
from dyngen.data.parameters_file import read_link_parameters  # noqa: E402
from dyngen.runtime import load  # noqa: E402


def short(effect: dict) -> str:
    name, joints, values = effect["effect"], effect["joints"], effect["values"]
    if name in ("payload", "coefficients"):
        extra = f"m = {values['p'][0]:g} kg, c = {values['p'][1:4]}" if name == "payload" else \
            f"masses, inertias +-{values['relative']:.0%}"
        return f"{name} ({extra})"
    if name == "tilt":
        return f"tilt {values['angle_deg']:g} deg"
    if name == "time_shift":
        return f"time shift {values['dt'] * 1e3:g} ms"
    numbers = "; ".join(f"{k} = {', '.join(f'{v:g}' for v in vs)}" for k, vs in values.items())
    return f"{name} j{','.join(map(str, joints))} ({numbers})"


def residual_rms(model, s, path) -> np.ndarray:
    m = read_csv(path)
    tau = np.array([model("rnea", *x, s) for x in zip(m.q, m.qd, m.qdd)])
    return np.sqrt(np.mean((m.tau - tau) ** 2, axis=0))


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("--out", type=Path, required=True, help="the case folder to write (replaced)")
    ap.add_argument("--rate", type=float, default=1000.0, help="sample rate [Hz] (default 1000)")
    ap.add_argument("--noise", type=float, default=0.05, help="torque noise sigma [Nm] (default 0.05)")
    ap.add_argument("--seed", type=int, default=0, help="noise and coefficient-error seed (default 0)")
    ap.add_argument("--results", type=Path, default=ROOT / "bench" / "results" / "withheld_cases.md")
    args = ap.parse_args(argv)

    model = load(ROOT / "generated" / "lwr")
    start = time.perf_counter()
    doc = write_cases(args.out, rate_hz=args.rate, noise=args.noise, seed=args.seed,
                      pi_full=lambda p: model("pi_full", p))
    seconds = time.perf_counter() - start
    size = sum(f.stat().st_size for f in args.out.iterdir())
    print(f"wrote {len(doc['cases'])} cases to {args.out} in {seconds:.1f} s ({size / 1e6:.0f} MB)")

    s = model("standard_from_dynamic", read_link_parameters(args.out / doc["params"], model.manifest["dof"]))
    rows = []
    for case in doc["cases"]:
        fit, held = (residual_rms(model, s, args.out / case[k]) for k in ("fit", "holdout"))
        truth = "; ".join(short(e) for e in case["effects"]) or "(noise only)"
        rows.append(f"| {case['name']} | {truth} | {' '.join(f'{x:.3f}' for x in held)} | "
                    f"{held.max() / args.noise:.1f} | {fit.max() / args.noise:.1f} |")
        print(rows[-1])
    table = "\n".join([
        "# Withheld-effect cases: residual of the nominal model\n",
        f"`python bench/withheld_cases.py --out DIR --rate {args.rate:g} --noise {args.noise:g} --seed {args.seed}`: "
        f"{len(doc['cases'])} cases, fit = Fourier excitation ({doc['trajectories']['fit']['seconds']:g} s), "
        f"held-out = Table V (28 s), {args.rate:g} Hz, noise sigma {args.noise:g} Nm; written in {seconds:.1f} s, "
        f"{size / 1e6:.0f} MB.\n",
        "RMS of tau_measured - rnea(params.yaml) per joint on the held-out trajectory, and the largest "
        "per-joint RMS over sigma on each trajectory (the noise alone gives 1.0).\n",
        "| case | truth | held-out RMS j1..j7 [Nm] | held-out max / sigma | fit max / sigma |",
        "|---|---|---|---|---|",
        *rows,
    ]) + "\n"
    write_file(args.results, table)
    print(f"table: {args.results}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
