"""Identification that generalises: the real LWR4+ (examples/lwr4-real) and the speed targets.

Part 1, real arm (fit on measurement 1, and on 1 + 2; test on measurement 3, a different and
faster trajectory used for nothing else), RMS of measured minus predicted torque per joint:
  - OLS: `dyngen identify --ols` (43 base coefficients, least squares, no friction);
  - paper: the paper's parameters (examples/lwr_paper_solution.yaml);
  - paper + friction: the simple model of /work/shared/reference/measured-data.md, per joint
    b + Fc tanh(qd / 0.02) + Fv qd fitted by least squares to the paper's residual on the fit data;
  - consistent: `dyngen identify --prior lwr_paper_solution.yaml` with default options
    (physically consistent links, friction, offsets, rotor inertia; the regularisation and the
    optional parts, a base tilt, a position ripple per joint and friction falling with speed per
    joint, chosen by 5-fold contiguous cross-validation on the fit data).
Part 2, speed on synthetic data: 30 s of 1 kHz 7-joint data (the LWR simulated in MuJoCo with
friction and rotor inertia, encoder-quantised positions differentiated through a 10 Hz
zero-phase filter, 0.05 Nm torque noise): identify_consistent with default options (every
choice by cross-validation) and with a given regularisation; the reduced problem solved by the extraction's barrier driver and,
beside it, as an SDP by cvxpy + Clarabel (the pseudo-inertia LMI; the inertia bounds about the
centre of mass are not convex in the standard parameters and are left out of the SDP).
Part 3, `dyngen excite` for the LWR: time and condition numbers.

    python bench/bench_identify.py [--skip-real] [--skip-speed]   # writes bench/results/identify.md
"""

from __future__ import annotations

import time
from pathlib import Path

from common import arguments, machine, on_path, table  # noqa: E402  (bench/ is sys.path[0])

ROOT = on_path()

from dyngen import blas  # noqa: E402

blas.use_one_thread()

import numpy as np  # noqa: E402

from dyngen.data import Conditioning, condition, read_recording  # noqa: E402
from dyngen.data.parameters_file import read_link_parameters  # noqa: E402
from dyngen.description import load_robot  # noqa: E402
from dyngen.identification import identify  # noqa: E402
from dyngen.identification.consistent import ConsistentOptions, identify_consistent  # noqa: E402
from dyngen.runtime import load  # noqa: E402

HERE = ROOT / "examples" / "lwr4-real"
FOLDER = ROOT / "generated" / "lwr"


def rms(x):
    return np.sqrt(np.mean(np.asarray(x) ** 2, axis=0))


def simple_friction(model, pi, fits, test):
    """Per joint b + Fc tanh(qd / 0.02) + Fv qd on the residual of pi, fitted on fits."""
    out = []
    for j in range(7):
        def cols(s):
            return np.column_stack([np.ones(len(s.t)), np.tanh(s.qd[:, j] / 0.02), s.qd[:, j]])
        A = np.vstack([cols(s) for s in fits])
        r = np.concatenate([s.tau[:, j] - (model.batch("regressor", s.q, s.qd, s.qdd) @ pi)[:, j] for s in fits])
        x, *_ = np.linalg.lstsq(A, r, rcond=None)
        out.append(rms(test.tau[:, j] - (model.batch("regressor", test.q, test.qd, test.qdd) @ pi)[:, j] - cols(test) @ x))
    return np.array(out)


def real(lines):
    robot = load_robot(ROOT / "examples" / "lwr.yaml")
    model = load(FOLDER)
    paper = read_link_parameters(ROOT / "examples" / "lwr_paper_solution.yaml", 7)
    pi_paper = model("pi_full", paper)
    test = condition(read_recording(HERE / "measurement_3.csv", 7))

    def pred(pi, s):
        return model.batch("regressor", s.q, s.qd, s.qdd) @ pi

    lines += ["## Real LWR4+: held-out RMS on measurement 3 [Nm]", "",
              "| fit on | model | J1 | J2 | J3 | J4 | J5 | J6 | J7 | every link consistent |",
              "|---|---|---:|---:|---:|---:|---:|---:|---:|---|"]
    for fit_names in (["measurement_1.csv"], ["measurement_1.csv", "measurement_2.csv"]):
        fits = [condition(read_recording(HERE / n, 7)) for n in fit_names]
        label = " + ".join(n.split("_")[1].split(".")[0] for n in fit_names)
        ols = identify(model, fits, "full")
        start = time.perf_counter()
        c = identify_consistent(robot, model, FOLDER, fits, ConsistentOptions(prior=paper))
        seconds = time.perf_counter() - start
        rows = {"OLS (`--ols`)": (rms(test.tau - pred(ols.values, test)), "-"),
                "paper": (rms(test.tau - pred(pi_paper, test)), "no (6 of 7 links fail)"),
                "paper + offset, Coulomb, viscous per joint": (simple_friction(model, pi_paper, fits, test), "no"),
                f"**consistent**, default options ({seconds:.1f} s)":
                    (rms(test.tau - c.predict(model, test)), "yes" if np.all(c.lambda_min >= 0.99e-7) else "NO")}
        best_other = np.min([v for k, (v, _) in rows.items() if not k.startswith("**")], axis=0)
        for name, (values, consistent) in rows.items():
            cells = " | ".join(f"{x:.3f}" for x in values)
            lines.append(f"| m{label} | {name} | {cells} | {consistent} |")
        ours = rows[[k for k in rows if k.startswith("**")][0]][0]
        lines.append(f"| m{label} | consistent beats every other on | " + " | ".join(
            "yes" if a < b else "**no**" for a, b in zip(ours, best_other)) + " | |")
        lines.append("")
        from dyngen.identification.consistent_output import groups_text

        lines.append(f"m{label}: lambda {c.regularisation:g}, cross-validation (lambda: score) "
                     + ", ".join(f"{a:g}: {b:.4g}" for a, b in c.selection) + f"; chosen on held-out stretches: "
                     f"{groups_text(c.groups)}; base tilt {c.tilt_deg():.2f} deg; viscous [Nm s/rad] "
                     + ", ".join(f"{x:.3g}" for x in c.friction["viscous"]) + "; lags of the Coulomb term [s] "
                     + ", ".join(f"{x:g}" for x in c.lags) + "; smoothing [rad/s] "
                     + ", ".join(f"{x:g}" for x in c.smoothing) + "; left out (not separable): "
                     + (", ".join(c.dropped_columns) or "none"))
        lines.append("")


def synthetic(seconds=30.0, rate=1000.0):
    from dataclasses import replace

    from simulation.mujoco_measurements import Effects, Trajectory, measure
    from oracles.random_params import random_parameters

    from dyngen.data.recording import Recording
    from dyngen.excitation import Settings, random_design

    import tempfile

    # the LWR without the paper's bounds (the random true parameters lie outside them), so that the
    # barrier and the SDP solve the same problem (the SDP cannot hold bounds on I about the CoM)
    text = (ROOT / "examples" / "lwr.yaml").read_text()
    text = text[:text.index("  bounds:")] + text[text.index("identified:"):]
    path = Path(tempfile.mkdtemp()) / "lwr_synthetic.yaml"
    path.write_text(text[:text.index("identified:")])
    robot = load_robot(path)
    p = random_parameters(7, 5, mass=(0.5, 3.0), second_moment=(0.002, 0.02))
    effects = Effects(coulomb={j: 0.3 + 0.1 * j for j in range(1, 8)}, viscous={j: 0.2 + 0.05 * j for j in range(1, 8)},
                      armature={j: 0.02 * j for j in range(3, 8)})
    t = np.arange(int(seconds * rate)) / rate
    m = measure(robot, p, Trajectory(t, random_design(robot, Settings(), 1)), effects, noise=0.05, seed=1)
    step = 2 * np.pi / 2 ** 20
    q = np.round((m.q + 1e-5 * np.random.default_rng(2).standard_normal(m.q.shape)) / step) * step
    s = condition(Recording("synthetic", t, q, None), Conditioning(cutoff=10.0, differentiate=True))
    return robot, replace(s, tau=m.tau)


def sdp(W, v, problem, r_map, margin):
    """min ||W pi(s) - v||^2 over s with the pseudo-inertia LMI, mass, centre-of-mass and total-mass
    bounds (cvxpy + Clarabel); r_map: K with pi = K s."""
    import cvxpy as cp

    n = problem.lower.size // 10
    s = cp.Variable(10 * n)
    cons = []
    for i in range(n):
        x = s[10 * i: 10 * i + 10]
        m, h = x[0], x[1:4]
        S = cp.bmat([[x[4], x[5], x[6]], [x[5], x[7], x[8]], [x[6], x[8], x[9]]])
        Sigma = 0.5 * cp.trace(S) * np.eye(3) - S - margin * np.eye(3)
        J = cp.bmat([[Sigma, cp.reshape(h, (3, 1), order="F")], [cp.reshape(h, (1, 3), order="F"), cp.reshape(m, (1, 1), order="F")]])
        cons += [(J + J.T) / 2 >> 0, m >= problem.lower[10 * i], m <= problem.upper[10 * i]]
        for a in range(3):
            cons += [h[a] >= problem.lower[10 * i + 1 + a] * m, h[a] <= problem.upper[10 * i + 1 + a] * m]
    if problem.total_mass is not None:
        total = sum(s[10 * i] for i in range(n))
        cons += [total >= problem.total_mass[0], total <= problem.total_mass[1]]
    prob = cp.Problem(cp.Minimize(cp.sum_squares(W @ (r_map @ s) - v)), cons)
    start = time.perf_counter()
    prob.solve(solver=cp.CLARABEL)
    return prob.value, time.perf_counter() - start, prob.status


def speed(lines):
    from dyngen.extraction import driver
    from dyngen.extraction.problem import Options as ExtractOptions
    from dyngen.extraction.problem import Stage, build_problem
    from dyngen.extraction.targets import Target
    from dyngen.identification.solver import robot_with_default_bounds
    from dyngen.parameters import dynamic_from_standard, standard_from_dynamic

    robot, s = synthetic()
    model = load(FOLDER)
    lines += ["## Speed: 30 s of 1 kHz data, 7 joints (synthetic, MuJoCo)", "", f"Machine: {machine()} (shared, loaded by other jobs: wall times vary by 2x).", ""]
    times = {}
    for label, options in (("default options: regularisation and optional parts by 5-fold cross-validation",
                            ConsistentOptions()),
                           ("given regularisation (optional parts still by cross-validation)",
                            ConsistentOptions(regularisation=0.0)),
                           ("given regularisation, no optional parts (one solve)",
                            ConsistentOptions(regularisation=0.0, candidates=()))):
        best = np.inf
        for _ in range(2):
            start = time.perf_counter()
            identify_consistent(robot, model, FOLDER, [s], options)
            best = min(best, time.perf_counter() - start)
        times[label] = best
    lines += table(["identify_consistent", "best of 2 [s]"], "lr")
    # (the regressor, the columns and the normal equations per part and joint are formed once; the
    # cross-validation's fits skip the driver's nearest-to-prior step and run two at a time)
    lines += [f"| {k} | {v:.2f} |" for k, v in times.items()]
    lines.append("")
    # the reduced problem: barrier driver vs SDP
    names = [e["standard"] for e in model.manifest["coefficients"]["full"]["expressions"]]
    r = len(names)
    Y = model.batch("regressor", s.q, s.qd, s.qdd).reshape(-1, r)
    W = np.linalg.cholesky(Y.T @ Y / Y.shape[0]).T
    v = np.linalg.solve(W.T, Y.T @ s.tau.reshape(-1) / Y.shape[0])
    problem = build_problem(robot_with_default_bounds(robot), ExtractOptions(global_algorithm="none", restarts=2))
    exe = driver.build(FOLDER)
    start = time.perf_counter()
    result = driver.run(exe, problem, Stage("x", [Target("full", W, v)], np.ones(70, bool), problem.reference.copy()),
                        ExtractOptions(global_algorithm="none", restarts=2))
    t_barrier = time.perf_counter() - start
    s0 = standard_from_dynamic(problem.center)
    K = np.column_stack([model("pi_full", dynamic_from_standard(s0 + np.eye(70)[k])) - model("pi_full", dynamic_from_standard(s0))
                         for k in range(70)])
    cost_b = float(np.sum((W @ model("pi_full", result.p) - v) ** 2))
    value, t_sdp, status = sdp(W, v, problem, K, 1e-7)
    lines += [*table(["reduced problem (43 coefficients, 7 links)", "time [s]", "cost ||W pi - v||^2"], "lrr"),
              f"| extraction's barrier driver (2 restarts + nearest-to-prior step, process start included) | {t_barrier:.2f} | {cost_b:.6g} |",
              f"| cvxpy + Clarabel SDP (no inertia bounds about the CoM), {status} | {t_sdp:.2f} | {value:.6g} |", ""]


def excite(lines):
    from dyngen.excitation import Settings, optimise

    robot = load_robot(ROOT / "examples" / "lwr.yaml")
    model = load(FOLDER)
    start = time.perf_counter()
    d = optimise(robot, model, Settings(seed=1))
    lines += ["## `dyngen excite` (LWR, 5 harmonics, 10 s period, seed 1)", "",
              f"{time.perf_counter() - start:.1f} s, {d.evaluations} evaluations; condition number {d.condition:.4g} "
              f"(columns scaled {d.scaled_condition:.4g}); median random trajectory with the same limits "
              f"{d.random_condition:.4g} (scaled {d.random_scaled_condition:.4g}).", ""]


def main():
    ap = arguments(__doc__, whole=True)
    ap.add_argument("--skip-real", action="store_true")
    ap.add_argument("--skip-speed", action="store_true")
    ap.add_argument("--skip-excite", action="store_true")
    args = ap.parse_args()
    lines = ["# Identification benchmark (`python bench/bench_identify.py`)", ""]
    if not args.skip_real:
        real(lines)
    if not args.skip_speed:
        speed(lines)
    if not args.skip_excite:
        excite(lines)
    out = ROOT / "bench" / "results" / "identify.md"
    out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
