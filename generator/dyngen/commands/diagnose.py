"""`dyngen diagnose`: where the gap between measured torques and the model lies, which
unmodelled effects explain it, and how far it shrinks on data used for nothing else."""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

from ..errors import InputError, printable
from ..options import add_arguments, resolve
from ..progress import Progress
from ..arguments import whole
from ..streaming.sample import MAX_ROWS
from .recordings import (MIN_DIAGNOSIS_SAMPLES, add_data_options, check_enough, check_headers, compiled_model,
                         conditioning_text, read_all)


def parser(prog="dyngen diagnose") -> argparse.ArgumentParser:
    from ..diagnosis import Options

    parser = argparse.ArgumentParser(prog=prog, description=(
        "Diagnose the gap between measured torques and the Newton-Euler model with given link parameters: "
        "where the residual lies (per joint, per phase of the motion), which unmodelled effects explain it "
        "(Coulomb friction with a fitted velocity scale, viscous, Stribeck and direction-dependent friction, "
        "position ripple, rotor inertia, sensor offset and gain, payload, tilted base, gravity scale, time "
        "shift) and how far it shrinks. Three roles for data: --data fits the effects' values, --select chooses "
        "the effects, --test is used only for the residual reported as held out. A simple model (per joint "
        "offset + Coulomb + viscous) is always reported beside the result. Writes report.md, diagnosis.json, "
        "effects.yaml, torques.png, residuals.png and, for consistent parameters, URDF and MJCF with the "
        "selected friction. Exit status 3 when the data cannot support a diagnosis (report.md, diagnosis.json and "
        "conditioning.png say why): a nominal residual over 1.5 times the measured torque under every conditioning "
        "tried, a joint's torque of the other sign or in other units, positions in degrees, torques without "
        "gravity, or link parameters far off; errors in the input exit with 2."))
    add_data_options(parser)
    parser.add_argument("--params", required=True, metavar="P.yaml",
                        help="link parameters: extraction output (links:), a solution file (solution:) or a robot "
                             "YAML (parameters.nominal)")
    parser.add_argument("--select", action="append", metavar="CSV",
                        help="recording(s) that choose the effects (default: 2-s blocks of the --data recordings, "
                             "every third block judging what the others fit, each third in turn)")
    parser.add_argument("--test", action="append", metavar="CSV",
                        help="recording(s) used for nothing but the reported held-out residual; best a different "
                             "trajectory (default: none, and the report says that nothing was held out)")
    parser.add_argument("--holdout", action="append", metavar="CSV", help="the same as --test")
    parser.add_argument("--control", action="append", metavar="CSV",
                        help="a control run of the same arm without what is looked for (e.g. unloaded beside a loaded "
                             "--data run): diagnosed apart with the same options; a finding also found there is "
                             "reported as the nominal model's error (diagnosis/across.py)")
    parser.add_argument("--split", metavar="F,S,T",
                        help="cut every --data recording in time into fit, select and test pieces of these "
                             "fractions (e.g. 0.6,0.2,0.2), each conditioned on its own")
    parser.add_argument("--out", default=None, metavar="DIR", help="output folder (default out/<robot>/diagnosis)")
    parser.add_argument("--force", action="store_true",
                        help="replace an output folder that holds files dyngen did not write (docs/untrusted-input.md)")

    parser.add_argument("--survey", action="store_true",
                        help="only the gap of every --data recording and the simple model, per recording and pooled, "
                             "and which recordings stand out; each recording read in blocks, on all cores "
                             "(recordings.md, recordings.json)")
    parser.add_argument("--max-rows", type=whole(MIN_DIAGNOSIS_SAMPLES, 10 ** 9), default=None, metavar="N",
                        help="a --data recording of more samples is diagnosed on evenly spread 6-s windows of at most "
                             "N samples in all, its gap and simple model reported over every sample (read in blocks: "
                             "memory independent of its length); so are --select, --test and each piece of --split, "
                             f"read in blocks (default {MAX_ROWS})")
    group = parser.add_argument_group("diagnosis")
    add_arguments(group, Options)
    group.add_argument("--no-reidentify", dest="reidentify", action="store_const", const=False,
                       default=argparse.SUPPRESS, help="never re-identify the link parameters (see --reidentify)")
    return parser


def main(argv, prog="dyngen diagnose") -> int:
    args = parser(prog).parse_args(argv)
    from ..data.split import parse_fractions
    from ..description import load_robot
    from ..diagnosis import Options, diagnose
    from ..terms import check_names
    from ..diagnosis.diagnosis_files import write_outputs
    from ..diagnosis.report_text import summary_lines
    from ..data.parameters_file import read_link_parameters

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
    if args.survey:
        from .survey import run_survey

        return run_survey(args, robot, p, progress)
    start = time.perf_counter()
    tests = (args.test or []) + (args.holdout or [])
    out = Path(args.out) if args.out else Path("out") / robot.name / "diagnosis"
    from ..output_paths import check_folder, results_folder, shown

    check_folder(out, [args.robot, args.params, *args.data, *(args.select or []), *tests, *(args.control or []),
                       args.model], args.force)
    # bad input fails before anything is announced or written
    max_rows = args.max_rows or MAX_ROWS
    if args.split:
        if args.select or tests:
            raise InputError("--split", "", "cuts the --data recordings into fit, select and test: give no "
                             "--select, --test or --holdout with it")
        from .long_diagnosis import read_split

        fit, select, test = read_split(args.data, robot, args, parse_fractions(args.split), max_rows)
        check_enough([*fit, *select, *test])
    else:  # --data read in blocks once the model is compiled (long_diagnosis.py); their headers now
        from .long_diagnosis import read_windows

        check_headers(args.data, robot, args)
        select = read_windows(args.select or [], robot, args, max_rows)
        test = read_windows(tests, robot, args, max_rows)
        check_enough([*select, *test])
    progress.say(f"dyngen diagnose: {robot.name} with {Path(args.params).name}, {len(args.data)} fit, {len(select)} "
                 f"select and {len(test)} test recording(s)")
    model = compiled_model(args, robot, progress)
    sampled = []
    if not args.split:
        from .long_diagnosis import read_fit

        with progress.step("read the --data recordings (in blocks)"):
            fit, sampled = read_fit(args.data, robot, args, model, p, max_rows)
        check_enough(fit)
    sources = {"params": printable(Path(args.params).name), "fit": [s.name for s in fit], "select": [s.name for s in select],
               "test": [s.name for s in test], "conditioning": conditioning_text(fit + select + test)}
    if sampled:
        sources["sampled"] = sampled
    from ..data.trust import EXIT_UNUSABLE, Unusable  # the diagnosis loads only once it runs
    from ..diagnosis.diagnosis_files import write_unusable

    try:
        with progress.step("residual, effects, selection, test"):
            result = diagnose(robot, model, p, fit, select or None, options, test=test)
    except Unusable as err:  # nothing claimed: the line, report.md and the figure that shows why
        with results_folder(out) as staging:  # written as one unit, as the full results are
            paths = write_unusable(err, staging, sources)
        paths = {k: shown(v, staging, out) for k, v in paths.items()}
        print(f"dyngen diagnose: {err.line}", file=sys.stderr)
        if not args.quiet:
            print(f"  written: {', '.join(str(v) for v in paths.values())}")
        return EXIT_UNUSABLE
    for path in args.control or []:  # findings also found in a control run: the model's error
        from ..diagnosis.across import compared

        control = read_all([path], robot, args)
        check_enough(control)
        try:
            with progress.step(f"control run {control[0].name}"):
                result = compared(result, diagnose(robot, model, p, control, None, options), control[0].name)
        except Unusable as err:
            result = replace(result, warnings=[*result.warnings, f"control run {control[0].name}: {err.line}"])
    with progress.step("report, JSON, figures, updated model"):
        with results_folder(out) as staging:  # the folder is written as one unit
            paths = write_outputs(result, robot, p, staging, sources, options.sign_velocity)
            if sampled:
                from .long_diagnosis import markdown

                with open(staging / "report.md", "a", encoding="utf-8") as f:
                    f.write(markdown(sampled))
        paths = {k: shown(v, staging, out) if isinstance(v, Path) else v for k, v in paths.items()}
    if not args.quiet:
        print(f"{robot.name}: diagnosis in {time.perf_counter() - start:.1f} s ({result.split})")
        print("\n".join(summary_lines(result)))
        written = [str(v) for k, v in paths.items() if k != "export skipped"]
        print(f"  written: {', '.join(written)}")
        if "export skipped" in paths:
            print(f"  URDF/MJCF not written: {paths['export skipped']}")
    elif result.warnings:
        print("\n".join(f"warning: {w}" for w in result.warnings), file=sys.stderr)
    return 0
