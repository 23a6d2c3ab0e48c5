"""Whether a refactor changes a result: runs `dyngen diagnose`, `identify` and `excite` on a
handful of cases with the dyngen of one generator/ folder and keeps every output file, so that two
runs (before and after the change) can be compared with `diff -r`.

    python bench/compare_outputs.py cases DIR             # the synthetic cases (once, shared by both runs)
    python bench/compare_outputs.py run GENERATOR CASES OUT  # every command with GENERATOR's dyngen
    python bench/compare_outputs.py diff OUT_BEFORE OUT_AFTER   # every file byte for byte

Cases: the withheld sample (/work/shared/data/withheld-sample), the real LWR4+ runs
(examples/lwr4-real), and synthetic LWR cases from the tests' simulation (stribeck_off_grid,
gain_tilt, payload_tilt, shift_coulomb, 200 Hz) whose effects exercise every term's candidate.
"""

from __future__ import annotations

import filecmp
import os
import re
import subprocess
import sys
from pathlib import Path

from common import arguments, on_path

ROOT = on_path()
WITHHELD = Path("/work/shared/data/withheld-sample")
REAL = ROOT / "examples" / "lwr4-real"
LWR = ROOT / "examples" / "lwr.yaml"
SYNTHETIC = ("stribeck_off_grid", "gain_tilt", "payload_tilt", "shift_coulomb", "stribeck")


def write_synthetic(folder: Path) -> None:
    from simulation.withheld_cases import COMPOSED_CASES, OFF_GRID_CASES, CASES, write_cases

    chosen = [c for c in (*CASES, *COMPOSED_CASES, *OFF_GRID_CASES) if c.name in SYNTHETIC]
    write_cases(folder, rate_hz=200.0, cases=chosen, fit_seconds=20.0)


def commands(cases: Path) -> dict:
    """case name -> the dyngen arguments (the output folder or file appended as {out})."""
    model = ["--model", str(ROOT / "generated" / "lwr")]
    out = {}
    for name in ("friction_24", "payload_offset"):
        d = WITHHELD / name
        base = ["diagnose", str(LWR), "--params", str(WITHHELD / "nominal.yaml"), *model,
                "--data", str(d / "excitation.csv"), "--test", str(d / "validation.csv")]
        out[f"diagnose-{name}"] = base + ["--out", "{out}"]
        out[f"identify-{name}"] = ["identify", str(LWR), *model, "--data", str(d / "excitation.csv"),
                                   "-o", "{out}/identified.yaml"]
    paper = str(ROOT / "examples" / "lwr_paper_solution.yaml")
    m = [str(REAL / f"measurement_{k}.csv") for k in (1, 2, 3)]
    out["diagnose-real-1-3"] = ["diagnose", str(LWR), "--params", paper, *model, "--data", m[0], "--test", m[2],
                                "--out", "{out}"]
    every = ("offset,coulomb,viscous,stribeck,direction,ripple,armature,gain,payload,tilt,gravity_scale,time_shift,"
             "coefficients")
    out["diagnose-real-all-effects"] = ["diagnose", str(LWR), "--params", paper, *model, "--data", m[2],
                                        "--effects", every, "--out", "{out}"]
    out["identify-real-ols"] = ["identify", str(LWR), *model, "--ols", "--data", m[0], "-o", "{out}/identified.yaml"]
    out["identify-real-consistent"] = ["identify", str(LWR), *model, "--data", m[0], "--prior", paper, "--friction",
                                       "coulomb,viscous,offset,armature,ripple", "--tilt", "-o",
                                       "{out}/identified.yaml"]
    for name in SYNTHETIC:
        out[f"diagnose-{name}"] = ["diagnose", str(LWR), "--params", str(cases / "params.yaml"), *model,
                                   "--data", str(cases / f"{name}.fit.csv"), "--test",
                                   str(cases / f"{name}.holdout.csv"), "--out", "{out}"]
    out["identify-gain_tilt"] = ["identify", str(LWR), *model, "--data", str(cases / "gain_tilt.fit.csv"),
                                 "-o", "{out}/identified.yaml"]
    out["excite-lwr"] = ["excite", str(LWR), *model, "--iterations", "8", "-q", "-o", "{out}/excitation.csv"]
    out["excite-lwr-logdet"] = ["excite", str(LWR), *model, "--iterations", "8", "--criterion", "logdet",
                                "--harmonics", "3", "-q", "-o", "{out}/excitation.csv"]
    out["excite-lwr-workspace"] = ["excite", str(LWR), *model, "--iterations", "4", "--harmonics", "3",
                                   "--workspace=-0.6,0.6,-0.6,0.6,0.2,1.2", "-o", "{out}/excitation.csv"]
    return out


def run(generator: Path, cases: Path, out: Path, only: list) -> int:
    env = dict(os.environ, PYTHONPATH=str(generator.resolve()), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    failed = 0
    for name, args in commands(cases).items():
        if only and name not in only:
            continue
        folder = out / name
        folder.mkdir(parents=True, exist_ok=True)
        args = [a.replace("{out}", str(folder)) for a in args]
        res = subprocess.run([sys.executable, "-m", "dyngen", *args], capture_output=True, text=True, env=env)
        (folder / "exit.txt").write_text(f"{res.returncode}\n{res.stderr}")
        print(name, res.returncode, flush=True)
        failed += res.returncode != 0
    return failed


def differences(before: Path, after: Path) -> list[str]:
    """Every output file that differs or is missing (exit.txt: the exit code and messages, its
    timings left out)."""
    out = []
    for folder in sorted(p for p in before.iterdir() if p.is_dir()):
        files = sorted(p.relative_to(folder) for p in folder.rglob("*") if p.is_file())
        for name in files:
            a, b = folder / name, after / folder.name / name
            if not b.is_file():
                out.append(f"{folder.name}/{name}: missing")
            elif name.name == "exit.txt":
                if re.sub(r"[0-9.]+ s\)", "s)", a.read_text()) != re.sub(r"[0-9.]+ s\)", "s)", b.read_text()):
                    out.append(f"{folder.name}/{name}: exit code or messages differ")
            elif not filecmp.cmp(a, b, shallow=False):
                out.append(f"{folder.name}/{name}: differs")
    return out


def main() -> int:
    parser = arguments(__doc__, whole=True)
    parser.add_argument("what", choices=("cases", "run", "diff"))
    parser.add_argument("paths", nargs="+", type=Path)
    parser.add_argument("--only", default="", help="comma-separated case names")
    a = parser.parse_args()
    if a.what == "cases":
        write_synthetic(a.paths[0])
        return 0
    if a.what == "diff":
        found = differences(a.paths[0], a.paths[1])
        cases = sum(p.is_dir() for p in a.paths[0].iterdir())
        print("\n".join(found) or f"{cases} cases: every output file byte-identical (timings aside)")
        return int(bool(found))
    return run(a.paths[0], a.paths[1], a.paths[2], [s for s in a.only.split(",") if s])


if __name__ == "__main__":
    raise SystemExit(main())
