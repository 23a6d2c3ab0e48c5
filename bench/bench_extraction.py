"""Extraction speed: dyngen's NLopt driver against SciPy on the same problems.

For each arm, identified coefficients are computed from known physically consistent
parameters inside the YAML's bounds, so an exact consistent solution exists. Success for a
restart: consistent (lambda_min(tr(I)/2 E - I) >= margin, bounds, total mass) and relative
coefficient error <= 1e-9. SciPy: dual_annealing on the objective plus a quadratic penalty of
the constraints (it takes bounds only), then SLSQP with the real constraints and gradients
(the alternative a user would write today). Both sides use the same compiled pi(p) and
Jacobian functions. Reported: time per restart, success rate, time to a successful solution.

    python bench/bench_extraction.py [--arms lwr panda] [--restarts 8] [--scipy-restarts 4]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.optimize import dual_annealing, minimize

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from dyngen.description import load_robot  # noqa: E402
from dyngen.extraction.problem import Options, build_problem, consistency_margin  # noqa: E402
from dyngen.extraction.run import extract  # noqa: E402
from dyngen.generate import generate  # noqa: E402
from dyngen.runtime import load  # noqa: E402
from test_extraction import consistent_inside_bounds, synthetic_yaml  # noqa: E402

KINDS = ("gravity", "inertia")


class Built:  # the small part of tests' Built that synthetic_yaml needs
    def __init__(self, yaml_path, model):
        self.yaml, self.c = yaml_path, model


def scipy_restart(model, problem, targets, options, seed):
    lower, upper = problem.lower, problem.upper
    n_links = problem.n_links

    def cost(p, grad=False):
        total, g = 0.0, np.zeros_like(p)
        for kind, (W, v) in targets.items():
            r = W @ model(f"pi_{kind}", p) - v
            total += r @ r
            if grad:
                g += 2 * model(f"pi_{kind}_jacobian", p).T @ (W.T @ r)
        return (total, g) if grad else total

    def constraints(p):  # >= 0 when satisfied
        values = [consistency_margin(p[10 * i: 10 * i + 10]) - options.margin for i in range(n_links)]
        if problem.total_mass:
            lo, hi = problem.total_mass
            values += [p[::10].sum() - lo, hi - p[::10].sum()]
        return np.array(values)

    def penalised(p):
        return cost(p) + 1e3 * np.sum(np.minimum(constraints(p), 0) ** 2)

    rng_start = np.random.default_rng(seed)
    x0 = lower + (upper - lower) * rng_start.uniform(size=lower.size)
    annealed = dual_annealing(penalised, list(zip(lower, upper)), x0=x0, seed=seed, maxiter=200, no_local_search=True)
    polished = minimize(lambda p: cost(p, True), annealed.x, jac=True, method="SLSQP",
                        bounds=list(zip(lower, upper)), constraints=[{"type": "ineq", "fun": constraints}],
                        options={"maxiter": 1000, "ftol": 1e-16})
    p = np.clip(polished.x, lower, upper)
    return p, cost(p), float(constraints(p).min())


def run_arm(name, restarts, scipy_restarts, tmp):
    base_yaml = ROOT / "examples" / f"{name}.yaml"
    robot = load_robot(base_yaml)
    out = generate(robot, tmp / "gen")
    model = load(out.folder)
    p_true = consistent_inside_bounds(robot, seed=3)
    path = synthetic_yaml(Built(base_yaml, model), p_true, tmp)
    synthetic = load_robot(path)
    options = Options(restarts=restarts)
    extract(synthetic, out.bases, out.folder, Options(restarts=1))  # build the driver outside the timing
    start = time.perf_counter()
    ex = extract(synthetic, out.bases, out.folder, options)
    dyngen_seconds = time.perf_counter() - start
    stage = ex.stages[-1]
    norm_v = np.sqrt(sum(np.sum(t.v ** 2) for t in ex.targets.values()))
    ok = (stage.restart_violations <= options.tolerance) & (np.sqrt(stage.restart_costs) <= 1e-9 * norm_v)
    targets = {k: (t.W, t.v) for k, t in ex.targets.items()}
    problem = build_problem(synthetic, options)
    scipy_ok, scipy_times = [], []
    for k in range(scipy_restarts):
        start = time.perf_counter()
        p, c, worst = scipy_restart(model, problem, targets, options, seed=k)
        scipy_times.append(time.perf_counter() - start)
        scipy_ok.append(worst >= -options.tolerance and np.sqrt(c) <= 1e-9 * norm_v)
    per_restart_dyngen = dyngen_seconds / restarts  # wall time, restarts run on all cores
    per_restart_scipy = float(np.mean(scipy_times))
    rate_d, rate_s = ok.mean(), float(np.mean(scipy_ok))
    to_success_d = per_restart_dyngen / max(rate_d, 1e-9)
    to_success_s = per_restart_scipy / rate_s if rate_s > 0 else float("inf")
    return dict(arm=name, dyngen_s=dyngen_seconds, restarts=restarts, rate_d=rate_d, per_d=per_restart_dyngen,
                scipy_n=scipy_restarts, per_s=per_restart_scipy, rate_s=rate_s,
                to_d=to_success_d, to_s=to_success_s)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--arms", nargs="+", default=["lwr", "panda", "puma560", "ur5"])
    parser.add_argument("--restarts", type=int, default=16)
    parser.add_argument("--scipy-restarts", type=int, default=4)
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.arms:
            row = run_arm(name, args.restarts, args.scipy_restarts, Path(tmp) / name)
            rows.append(row)
            print(row, flush=True)
    lines = ["# Extraction: dyngen (NLopt driver) vs SciPy (dual_annealing + SLSQP)", "",
             "Coefficients from known consistent parameters inside each YAML's bounds (an exact consistent",
             "solution exists). Success: consistent and relative coefficient error <= 1e-9. dyngen's",
             "restarts run on all cores (wall time / restarts); SciPy runs one restart at a time.", "",
             "| arm | dyngen: restarts, success | dyngen s/restart | SciPy: restarts, success | SciPy s/restart | "
             "time to a success: dyngen | SciPy | ratio |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ratio = r["to_s"] / r["to_d"] if np.isfinite(r["to_s"]) else float("inf")
        lines.append(f"| {r['arm']} | {r['restarts']}, {100 * r['rate_d']:.0f}% | {r['per_d']:.3f} | "
                     f"{r['scipy_n']}, {100 * r['rate_s']:.0f}% | {r['per_s']:.2f} | {r['to_d']:.3f} s | "
                     f"{r['to_s']:.2f} s | {ratio:.0f}x |")
    text = "\n".join(lines) + "\n"
    (ROOT / "bench" / "results" / "extraction.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
