"""`dyngen identify` and `dyngen diagnose`: the commands that take measured data."""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

from .errors import InputError
from .options import add_arguments, resolve
from .progress import Progress

MIN_DIAGNOSIS_SAMPLES = 50


def _data_options(parser: argparse.ArgumentParser) -> None:
    from .data import Conditioning

    parser.add_argument("robot", metavar="ROBOT.yaml", help="robot description (docs/conventions.md)")
    parser.add_argument("--data", action="append", required=True, metavar="CSV",
                        help="a recording: header t, q1..qN, tau1..tauN, optional qd*, qdd*; repeatable")
    add_arguments(parser.add_argument_group("signal conditioning"), Conditioning)
    parser.add_argument("--model", metavar="DIR",
                        help="an already generated folder of this robot (default: generate it first)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors and warnings")


def _enough(name: str, t) -> None:
    if len(t) < MIN_DIAGNOSIS_SAMPLES:
        raise InputError(name, "", f"{len(t)} samples; a diagnosis needs at least {MIN_DIAGNOSIS_SAMPLES} "
                         "(seconds of motion at the recording's rate)")


def _conditioning(args):
    from .data import Conditioning

    return resolve(Conditioning, args, {})


def _conditioning_text(signals) -> str:
    """What conditioning did, per recording (the automatic choice differs between recordings)."""
    notes = sorted({s.note for s in signals})
    return notes[0] if len(notes) == 1 else "; ".join(f"{s.name}: {s.note}" for s in signals)


def _model(args, robot, progress):
    """The compiled model: the given folder, or one generated now into a temporary folder."""
    from .runtime import load

    if args.model:
        folder = Path(args.model)
        if not (folder / "manifest.json").exists():
            raise InputError(str(folder), "", "not a generated folder (no manifest.json)")
        model = load(folder)
        if model.manifest["robot"] != robot.name or model.manifest["dof"] != robot.dof:
            raise InputError(str(folder), "manifest.json", f"the folder is for {model.manifest['robot']}, "
                             f"not {robot.name} ({robot.dof} joints)")
        return model
    from .generate import generate

    generated = generate(robot, None, progress)  # into the per-user cache, not the user's folders
    with progress.step("compile the generated C"):
        return load(generated.folder)


def _read(paths, robot, args, require_torques=True, required=()):
    from .data import condition, read_recording

    return [condition(read_recording(p, robot.dof, require_torques, required), _conditioning(args)) for p in paths]


def identify_parser(prog="dyngen identify") -> argparse.ArgumentParser:
    from .identification.consistent import ConsistentOptions
    from .identification.options import Options

    parser = argparse.ArgumentParser(prog=prog, description=(
        "Identify from recordings. --kind full (default): physically consistent link parameters with "
        "per-joint friction, offset and rotor inertia (weighted least squares subject to consistency of every "
        "link, the YAML's bounds and total mass; --ols for plain least squares), written with URDF and MJCF. "
        "Otherwise base coefficients by least squares (the paper's eq. 11), as the `identified:` YAML block "
        "that `dyngen extract` reads. --kind full uses torque "
        "trajectories (Y(q, qd, qdd) pi = tau); gravity reads the torques as gravity torques g(q) (static "
        "poses or the FRI's g(q), eq. 9); inertia reads the stacked inertia matrix from columns M11, M12, ... "
        "(eq. 10). Reports the regressor's condition number, every coefficient's standard deviation and "
        "the coefficients the data do not excite."))
    _data_options(parser)
    add_arguments(parser.add_argument_group("identification"), Options)
    parser.add_argument("-o", "--output", metavar="FILE",
                        help="where to write the YAML (default out/<robot>/identified_<kind>.yaml)")
    group = parser.add_argument_group("physically consistent identification (--kind full, the default)")
    group.add_argument("--prior", metavar="P.yaml",
                       help="link parameters to regularise toward and to keep what the data do not see near "
                            "(default: the YAML's parameters.nominal)")
    group.add_argument("--select", action="append", metavar="CSV",
                       help="recording(s) to choose the regularisation on (never fitted)")
    add_arguments(group, ConsistentOptions)
    return parser


def cmd_identify(argv, prog="dyngen identify") -> int:
    args = identify_parser(prog).parse_args(argv)
    from .identification.consistent_cli import run_consistent
    from .identification.options import Options

    options = resolve(Options, args, {})
    from .description import load_robot
    from .identification import identified_yaml, identify, summary_table
    from .identification.samples import stacked_inertia_columns

    robot = load_robot(args.robot)
    progress = Progress(quiet=args.quiet)
    kind = options.kind
    required = tuple(_inertia_names(robot)) if kind == "inertia" else ()
    # Bad input fails before anything is announced or written.
    signals = _read(args.data, robot, args, require_torques=kind != "inertia", required=required)
    progress.say(f"dyngen identify: {robot.name}, {kind} coefficients from {len(args.data)} recording(s)")
    model = _model(args, robot, progress)
    if kind == "full" and not options.ols:
        return run_consistent(args, robot, model, signals, progress)
    if kind == "inertia":
        assert stacked_inertia_columns(model.manifest) == list(required)
    with progress.step("least squares"):
        estimate = identify(model, signals, kind)
    out = Path(args.output) if args.output else Path("out") / robot.name / f"identified_{kind}.yaml"
    from .atomic import write_file

    write_file(out, identified_yaml(robot.name, {kind: estimate}, [Path(p).name for p in args.data],
                                    _conditioning_text(signals)))
    if not args.quiet:
        print(f"{robot.name}: {len(estimate.names)} {kind} coefficients from {estimate.rows} equations; "
              f"condition number {estimate.condition:.3g} (columns scaled {estimate.scaled_condition:.3g}); "
              f"residual RMS {estimate.residual_rms:.4g}")
        print("\n".join("  " + line for line in summary_table(kind, estimate).splitlines()))
        for w in [*estimate.warnings(), *(w for s in signals for w in s.warnings)]:
            print(f"  warning: {w}")
        print(f"  written: {out}")
    return 0


def _inertia_names(robot):
    n = robot.dof
    return [f"M{j + 1}{k + 1}" for j in range(n) for k in range(j, n)]


def diagnose_parser(prog="dyngen diagnose") -> argparse.ArgumentParser:
    from .diagnosis import Options

    parser = argparse.ArgumentParser(prog=prog, description=(
        "Diagnose the gap between measured torques and the Newton-Euler model with given link parameters: "
        "where the residual lies (per joint, per phase of the motion), which unmodelled effects explain it "
        "(Coulomb friction with a fitted velocity scale, viscous, Stribeck and direction-dependent friction, "
        "position ripple, rotor inertia, sensor offset and gain, payload, tilted base, gravity scale, time "
        "shift) and how far it shrinks. Three roles for data: --data fits the effects' values, --select chooses "
        "the effects, --test is used only for the residual reported as held out. A simple model (per joint "
        "offset + Coulomb + viscous) is always reported beside the result. Writes report.md, diagnosis.json, "
        "effects.yaml, torques.png, residuals.png and, for consistent parameters, URDF and MJCF with the "
        "selected friction."))
    _data_options(parser)
    parser.add_argument("--params", required=True, metavar="P.yaml",
                        help="link parameters: extraction output (links:), a solution file (solution:) or a robot "
                             "YAML (parameters.nominal)")
    parser.add_argument("--select", action="append", metavar="CSV",
                        help="recording(s) that choose the effects (default: every third 2-s block of the --data "
                             "recordings)")
    parser.add_argument("--test", action="append", metavar="CSV",
                        help="recording(s) used for nothing but the reported held-out residual; best a different "
                             "trajectory (default: none, and the report says that nothing was held out)")
    parser.add_argument("--holdout", action="append", metavar="CSV", help="the same as --test")
    parser.add_argument("--split", metavar="F,S,T",
                        help="cut every --data recording in time into fit, select and test pieces of these "
                             "fractions (e.g. 0.6,0.2,0.2), each conditioned on its own")
    parser.add_argument("--out", default=None, metavar="DIR", help="output folder (default out/<robot>/diagnosis)")
    add_arguments(parser.add_argument_group("diagnosis"), Options)
    return parser


def cmd_diagnose(argv, prog="dyngen diagnose") -> int:
    args = diagnose_parser(prog).parse_args(argv)
    from .data import condition, read_recording
    from .data.split import parse_fractions, split_recording
    from .description import load_robot
    from .diagnosis import Options, diagnose
    from .diagnosis.effects import check_names
    from .diagnosis.outputs import write_outputs
    from .diagnosis.report import summary_lines
    from .data.parameters_file import read_link_parameters

    options = resolve(Options, args, {})
    if options.effects == ():  # `--effects ""`: no list given, the default effects
        options = replace(options, effects=None)
    try:  # unknown names fail here, naming the option, before anything runs
        check_names(options.effects or ())
    except ValueError as err:
        raise InputError("--effects", "", str(err)) from None
    robot = load_robot(args.robot)
    p = read_link_parameters(args.params, robot.dof)
    progress = Progress(quiet=args.quiet)
    start = time.perf_counter()
    tests = (args.test or []) + (args.holdout or [])
    # bad input fails before anything is announced or written
    if args.split:
        if args.select or tests:
            raise InputError("--split", "", "cuts the --data recordings into fit, select and test: give no "
                             "--select, --test or --holdout with it")
        fractions = parse_fractions(args.split)
        pieces = [split_recording(read_recording(x, robot.dof), fractions) for x in args.data]
        for recording in (r for rs in pieces for r in rs if r is not None):
            _enough(recording.name, recording.t)
        fit, select, test = ([condition(r[k], _conditioning(args)) for r in pieces if r[k] is not None]
                             for k in range(3))
    else:
        fit = _read(args.data, robot, args)
        select = _read(args.select, robot, args) if args.select else []
        test = _read(tests, robot, args) if tests else []
        for path, recording in zip([*args.data, *(args.select or []), *tests], [*fit, *select, *test]):
            _enough(Path(path).name, recording.t)
    progress.say(f"dyngen diagnose: {robot.name} with {Path(args.params).name}, {len(fit)} fit, {len(select)} "
                 f"select and {len(test)} test recording(s)")
    model = _model(args, robot, progress)
    with progress.step("residual, effects, selection, test"):
        result = diagnose(robot, model, p, fit, select or None, options, test=test)
    out = Path(args.out) if args.out else Path("out") / robot.name / "diagnosis"
    sources = {"params": Path(args.params).name, "fit": [s.name for s in fit], "select": [s.name for s in select],
               "test": [s.name for s in test], "conditioning": _conditioning_text(fit + select + test)}
    with progress.step("report, JSON, figures, updated model"):
        paths = write_outputs(result, robot, p, out, sources, options.sign_velocity)
    if not args.quiet:
        print(f"{robot.name}: diagnosis in {time.perf_counter() - start:.1f} s ({result.split})")
        print("\n".join(summary_lines(result)))
        written = [str(v) for k, v in paths.items() if k != "export skipped"]
        print(f"  written: {', '.join(written)}")
        if "export skipped" in paths:
            print(f"  URDF/MJCF not written: {paths['export skipped']}")
    elif result.warnings:
        import sys

        print("\n".join(f"warning: {w}" for w in result.warnings), file=sys.stderr)
    return 0
