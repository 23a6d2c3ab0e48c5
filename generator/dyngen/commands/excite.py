"""`dyngen excite ROBOT.yaml`: an optimised excitation trajectory as a CSV a controller can play."""

from __future__ import annotations

import argparse
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..options import add_arguments, option, resolve
from ..progress import Progress


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


@dataclass(frozen=True)
class Sampling:
    """How the designed trajectory is written (its design: design.Settings)."""

    rate: float = option(1000.0, "CSV sample rate", metavar="HZ", bounds=(1, 100_000))
    periods: int = option(1, "periods written", metavar="K", bounds=(1, 1000))


def parser(prog="dyngen excite") -> argparse.ArgumentParser:
    from ..excitation.design import Settings

    result = argparse.ArgumentParser(prog=prog, description=(
        "Design a periodic excitation trajectory (finite Fourier series, at rest at its start and end) that "
        "minimises the condition number of the identification matrix (base regressor with per-joint Coulomb, "
        "viscous, offset and rotor-inertia columns) within the YAML's joint position, velocity and acceleration "
        "limits, optionally keeping the flange inside a box. Writes a CSV (t, q, qd, qdd), a plot and a "
        "summary with the condition number of a random trajectory with the same limits beside it."))
    result.add_argument("robot", metavar="ROBOT.yaml")
    result.add_argument("-o", "--output", metavar="CSV", help="default out/<robot>/excitation.csv")
    add_arguments(result, Sampling)
    add_arguments(result, Settings)
    result.add_argument("--workspace", metavar="XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX",
                        help="keep the flange (last DH frame's origin) inside this box [m]")
    result.add_argument("--model", metavar="DIR", help="an already generated folder of this robot")
    result.add_argument("-q", "--quiet", action="store_true")
    result.add_argument("--force", action="store_true",
                        help="replace an output folder that holds files dyngen did not write (docs/untrusted-input.md)")
    return result


def main(argv, prog="dyngen excite") -> int:
    from ..excitation.design import Settings

    command_line = parser(prog)
    args = command_line.parse_args(argv)
    sampling, settings = resolve(Sampling, args, {}), resolve(Settings, args, {})
    samples = sampling.rate * settings.period * sampling.periods
    if samples > MAX_SAMPLES:
        command_line.error(f"--rate x --period x --periods gives {samples:.3g} samples; at most {MAX_SAMPLES:g}")
    from ..atomic import write_file
    from ..description import load_robot
    from ..excitation.design import check_limits, limits_of, optimise
    from ..output_paths import check_file
    from .recordings import compiled_model

    robot = load_robot(args.robot)
    progress = Progress(quiet=args.quiet)
    out = Path(args.output) if args.output else Path("out") / robot.name / "excitation.csv"
    for path in (out, out.with_suffix(".png")):  # the output path policy, before any work
        check_file(path, [args.robot, args.model])
    limits = limits_of(robot)  # missing limits fail before anything runs
    if args.workspace:
        try:
            workspace = tuple(float(x) for x in args.workspace.split(","))
        except ValueError:
            workspace = ()
        if len(workspace) != 6 or any(workspace[2 * k] >= workspace[2 * k + 1] for k in range(3)):
            raise InputError("--workspace", "", f'expected XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX with min < max, got "{args.workspace}"')
        settings = replace(settings, workspace=workspace)
    progress.say(f"dyngen excite: {robot.name}, {settings.harmonics} harmonics, period {settings.period:g} s, "
                 f"seed {settings.seed}")
    model = compiled_model(args, robot, progress)
    with progress.step("optimise the Fourier coefficients"):
        design = optimise(robot, model, settings)
    t = np.arange(int(round(settings.period * sampling.periods * sampling.rate)) + 1) / sampling.rate
    q, qd, qdd = design.trajectory(t)
    problems = check_limits(robot, t, q, qd, qdd, settings.workspace)
    if problems:  # cannot happen by construction; never write a trajectory that breaks a limit
        raise InputError(args.robot, "joints[].limits", "; ".join(problems[:3]))
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
        print(f"  written: {out} ({t.size} samples at {sampling.rate:g} Hz), {plot}")
    return 0
