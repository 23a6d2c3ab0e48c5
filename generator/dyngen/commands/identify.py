"""`dyngen identify`: physically consistent link parameters with friction from recordings
(identification/consistent.py), or base coefficients by least squares."""

from __future__ import annotations

import argparse
from pathlib import Path
from ..arguments import whole
from ..options import add_arguments, resolve
from ..progress import Progress
from .recordings import HELD_ROWS, add_data_options, compiled_model, read_sources


def parser(prog="dyngen identify") -> argparse.ArgumentParser:
    from ..identification.consistent import ConsistentOptions
    from ..identification.identify_options import Options

    parser = argparse.ArgumentParser(prog=prog, description=(
        "Identify from recordings. --kind full (default): physically consistent link parameters with "
        "per-joint friction, offset and rotor inertia (weighted least squares subject to consistency of every "
        "link, the YAML's bounds and total mass; --ols for plain least squares), written with URDF and MJCF. "
        "Otherwise base coefficients by least squares (the paper's eq. 11), as the `identified:` YAML block "
        "that `dyngen extract` reads. --kind full uses torque "
        "trajectories (Y(q, qd, qdd) pi = tau); gravity reads the torques as gravity torques g(q) (static "
        "poses or the FRI's g(q), eq. 9); inertia reads the stacked inertia matrix from columns M11, M12, ... "
        "(eq. 10). Reports the regressor's condition number, every coefficient's standard deviation and "
        "the coefficients the data do not excite. Exit status 3, with nothing written (every kind but inertia): "
        "a --data or --select recording on which the nominal model (--prior, else parameters.nominal) leaves a "
        "residual over 1.5 times the measured torque on a joint under every conditioning tried (unless a rigid-body "
        "fit of the data explains it: then the links are what is off, and identification goes on), e.g. torques that "
        "do not belong to the positions, a joint's torque of the other sign or in other units, positions in "
        "degrees (docs/measured-data.md); errors in the input exit with 2."))
    add_data_options(parser)
    add_arguments(parser.add_argument_group("identification"), Options)
    parser.add_argument("-o", "--output", metavar="FILE",
                        help="where to write the YAML (default out/<robot>/identified_<kind>.yaml)")
    parser.add_argument("--force", action="store_true",
                        help="replace an output folder that holds files dyngen did not write (docs/untrusted-input.md)")

    group = parser.add_argument_group("physically consistent identification (--kind full, the default)")
    group.add_argument("--prior", metavar="P.yaml",
                       help="link parameters to regularise toward and to keep what the data do not see near "
                            "(default: the YAML's parameters.nominal)")
    group.add_argument("--select", action="append", metavar="CSV",
                       help="recording(s) to choose the regularisation on (never fitted)")
    group.add_argument("--max-rows", type=whole(16, 10 ** 9), default=HELD_ROWS, metavar="N",
                       help="a --data or --select recording of more samples, with qd and qdd recorded and no filter "
                            "asked for, is read from its file in blocks on every pass (memory independent of its "
                            "length; its columns as recorded, without the repairs of uneven stamps that need the "
                            f"whole recording); default {HELD_ROWS}")
    add_arguments(group, ConsistentOptions)
    return parser


def main(argv, prog="dyngen identify") -> int:
    args = parser(prog).parse_args(argv)
    from .identify_consistent import run_consistent
    from ..identification.identify_options import Options

    options = resolve(Options, args, {})
    from ..description import load_robot

    robot = load_robot(args.robot)
    progress = Progress(quiet=args.quiet)
    kind = options.kind
    required = tuple(_inertia_names(robot)) if kind == "inertia" else ()
    # Bad input fails before anything is announced or written.
    out = check_outputs(args, robot, kind, options.ols)
    if kind != "full" or options.ols:  # least squares: accumulated per recording, in parallel
        from .identify_least_squares import run_least_squares

        return run_least_squares(args, robot, kind, required, progress, out)
    sources = read_sources(args.data, robot, args)  # in blocks where they can be (identification/blocks.py)
    progress.say(f"dyngen identify: {robot.name}, {kind} coefficients from {len(args.data)} recording(s)")
    model = compiled_model(args, robot, progress)
    return run_consistent(args, robot, model, sources, progress, out)


def check_outputs(args, robot, kind: str, ols: bool) -> Path:
    """The output path policy (dyngen.output_paths) for every file this run writes, before any work."""
    from ..output_paths import check_file

    consistent = kind == "full" and not ols
    out = Path(args.output) if args.output else Path("out") / robot.name / (
        "identified_consistent.yaml" if consistent else f"identified_{kind}.yaml")
    files = [out, out.with_suffix(".md"), out.parent / f"{robot.name}.urdf", out.parent / f"{robot.name}.xml"]
    if not consistent:  # least squares: the YAML, and the per-recording table with several recordings
        files = [out, out.with_suffix(".recordings.md")]
    inputs = [args.robot, *args.data, *(getattr(args, "select", None) or []), getattr(args, "prior", None), args.model]
    for path in files:
        check_file(path, inputs)
    return out


def _inertia_names(robot):
    n = robot.dof
    return [f"M{j + 1}{k + 1}" for j in range(n) for k in range(j, n)]
