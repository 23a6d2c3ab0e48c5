"""`dyngen excite ROBOT.yaml`: an optimised excitation trajectory as a CSV a controller can play."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..arguments import real, whole
from ..errors import InputError
from ..progress import Progress


def forward_flange(robot):
    """q (T, N) -> flange position (T, 3) in the base frame, from the DH table (numeric)."""
    from ..export.frames import placements

    places = placements(robot)

    def flange(q):
        q = np.atleast_2d(np.asarray(q, dtype=float))
        T = np.broadcast_to(np.eye(4), (q.shape[0], 4, 4)).copy()
        for i, (joint, place) in enumerate(zip(robot.joints, places)):
            J = np.broadcast_to(np.eye(4), T.shape).copy()
            if joint.revolute:
                c, s = np.cos(q[:, i]), np.sin(q[:, i])
                J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1] = c, -s, s, c
            else:
                J[:, 2, 3] = q[:, i]
            T = T @ place.origin @ J
        return (T @ places[-1].post)[:, :3, 3]

    return flange


def csv_text(t, q, qd, qdd) -> str:
    n = q.shape[1]
    header = ["t"] + [f"q{j}" for j in range(1, n + 1)] + [f"qd{j}" for j in range(1, n + 1)] + \
        [f"qdd{j}" for j in range(1, n + 1)]
    rows = [",".join(header)]
    for k in range(t.size):
        rows.append(",".join(f"{x:.10g}" for x in (t[k], *q[k], *qd[k], *qdd[k])))
    return "\n".join(rows) + "\n"


def figure(robot, design, t, q, qd, qdd, limits, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..atomic import write_figure

    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    centre, half = (limits.upper + limits.lower) / 2, (limits.upper - limits.lower) / 2
    for j in range(q.shape[1]):
        axes[0].plot(t, (q[:, j] - centre[j]) / half[j], label=f"joint {j + 1}")
        axes[1].plot(t, qd[:, j] / limits.velocity[j])
        axes[2].plot(t, qdd[:, j] / limits.acceleration[j])
    for ax, name in zip(axes, ("position (-1, 1: limits)", "velocity / limit", "acceleration / limit")):
        ax.set_ylabel(name)
        ax.axhline(1, color="k", lw=0.5)
        ax.axhline(-1, color="k", lw=0.5)
        ax.grid(alpha=0.3)
    axes[0].legend(ncol=4, fontsize=8)
    axes[2].set_xlabel("t [s]")
    axes[0].set_title(f"{robot.name}: excitation, cond {design.condition:.3g} "
                      f"(random with the same limits: {design.random_condition:.3g})")
    fig.tight_layout()
    write_figure(path, fig, 100)
    plt.close(fig)


MAX_SAMPLES = 1e7  # rows of the written CSV (about 3 hours at 1 kHz)


def cmd_excite(argv, prog="dyngen excite") -> int:
    parser = argparse.ArgumentParser(prog=prog, description=(
        "Design a periodic excitation trajectory (finite Fourier series, at rest at its start and end) that "
        "minimises the condition number of the identification matrix (base regressor with per-joint Coulomb, "
        "viscous, offset and rotor-inertia columns) within the YAML's joint position, velocity and acceleration "
        "limits, optionally keeping the flange inside a box. Writes a CSV (t, q, qd, qdd), a plot and a "
        "summary with the condition number of a random trajectory with the same limits beside it."))
    parser.add_argument("robot", metavar="ROBOT.yaml")
    parser.add_argument("-o", "--output", metavar="CSV", help="default out/<robot>/excitation.csv")
    parser.add_argument("--rate", type=real(1, 100000), default=1000.0, metavar="HZ", help="CSV sample rate (default 1000)")
    parser.add_argument("--period", type=real(0.1, 3600), default=10.0, metavar="S", help="period [s] (default 10)")
    parser.add_argument("--periods", type=whole(1, 1000), default=1, metavar="K", help="periods written (default 1)")
    parser.add_argument("--harmonics", type=whole(1, 50), default=5, metavar="L", help="harmonics per joint (default 5)")
    parser.add_argument("--seed", type=whole(0, 2**31 - 1), default=1, help="seed of every random draw (default 1)")
    parser.add_argument("--margin", type=real(0, 1, above=True), default=0.95, help="fraction of each limit used (default 0.95)")
    parser.add_argument("--criterion", choices=("cond", "logdet"), default="cond")
    parser.add_argument("--iterations", type=whole(1, 100000), default=60, help="optimiser iterations (default 60)")
    parser.add_argument("--workspace", metavar="XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX",
                        help="keep the flange (last DH frame's origin) inside this box [m]")
    parser.add_argument("--model", metavar="DIR", help="an already generated folder of this robot")
    parser.add_argument("-q", "--quiet", action="store_true")
    args = parser.parse_args(argv)
    if args.rate * args.period * args.periods > MAX_SAMPLES:
        parser.error(f"--rate x --period x --periods gives {args.rate * args.period * args.periods:.3g} samples; "
                     f"at most {MAX_SAMPLES:g}")
    from ..description import load_robot
    from ..measured_cli import _model
    from .design import Settings, check_limits, limits_of, optimise

    robot = load_robot(args.robot)
    limits = limits_of(robot)  # missing limits fail before anything runs
    workspace = None
    if args.workspace:
        try:
            workspace = tuple(float(x) for x in args.workspace.split(","))
        except ValueError:
            workspace = ()
        if len(workspace) != 6 or any(workspace[2 * k] >= workspace[2 * k + 1] for k in range(3)):
            raise InputError("--workspace", "", f'expected XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX with min < max, got "{args.workspace}"')
    for name, value, ok in (("--rate", args.rate, args.rate > 0), ("--period", args.period, args.period > 0),
                            ("--periods", args.periods, args.periods >= 1),
                            ("--margin", args.margin, 0 < args.margin <= 1)):
        if not ok:
            raise InputError(name, "", f"{value} is out of range")
    progress = Progress(quiet=args.quiet)
    progress.say(f"dyngen excite: {robot.name}, {args.harmonics} harmonics, period {args.period:g} s, seed {args.seed}")
    model = _model(args, robot, progress)
    settings = Settings(seed=args.seed, period=args.period, harmonics=args.harmonics, margin=args.margin,
                        max_iterations=args.iterations, workspace=workspace, criterion=args.criterion)
    with progress.step("optimise the Fourier coefficients"):
        design = optimise(robot, model, settings, forward_flange(robot) if workspace else None)
    t = np.arange(int(round(args.period * args.periods * args.rate)) + 1) / args.rate
    q, qd, qdd = design.trajectory(t)
    problems = check_limits(robot, t, q, qd, qdd)
    if workspace:
        box = np.asarray(workspace).reshape(3, 2)
        where = forward_flange(robot)(q)
        outside = np.flatnonzero(~np.all((where >= box[:, 0]) & (where <= box[:, 1]), axis=1))
        if outside.size:
            problems.append(f"the flange leaves the workspace box at t = {t[outside[0]]:.4g} s")
    if problems:  # cannot happen by construction; never write a trajectory that breaks a limit
        raise InputError(args.robot, "joints[].limits", "; ".join(problems[:3]))
    out = Path(args.output) if args.output else Path("out") / robot.name / "excitation.csv"
    from ..atomic import write_file

    write_file(out, csv_text(t, q, qd, qdd))
    plot = out.with_suffix(".png")
    figure(robot, design, t, q, qd, qdd, limits, plot)
    if not args.quiet:
        use = lambda x, lim: ", ".join(f"{v:.2f}" for v in np.max(np.abs(x), axis=0) / lim)  # noqa: E731
        print(f"{robot.name}: excitation in {design.seconds:.1f} s ({design.evaluations} evaluations)")
        print(f"  condition number {design.condition:.4g} (columns scaled {design.scaled_condition:.4g}); "
              f"a random trajectory with the same limits: {design.random_condition:.4g} "
              f"(scaled {design.random_scaled_condition:.4g})")
        print(f"  share of the limit used per joint: velocity {use(qd, limits.velocity)}; "
              f"acceleration {use(qdd, limits.acceleration)}")
        print(f"  starts and ends at rest at q = {', '.join(f'{x:.3f}' for x in q[0])}")
        print(f"  written: {out} ({t.size} samples at {args.rate:g} Hz), {plot}")
    return 0
