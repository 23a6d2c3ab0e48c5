"""The `dyngen` command."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from . import __version__, blas

blas.use_one_thread()  # before numpy loads: the imports below load it

from .errors import DriverError, Infeasible, InputError  # noqa: E402
from .progress import Progress  # noqa: E402

MAIN_HELP = """\
dyngen: robot dynamic models as exact, standalone C from a DH table.

  dyngen ROBOT.yaml [options]          the main job: generate, then (when the YAML has identified
                                       coefficients and bounds) extract and export
  dyngen generate ROBOT.yaml [-o DIR]  derive, reduce to base coefficients, emit C into DIR/<name>/
  dyngen extract ROBOT.yaml [options]  physically consistent link parameters from the identified
                                       coefficients, written to OUT/<name>/
  dyngen identify ROBOT.yaml --data a.csv [--kind full|gravity|inertia]
                                       base coefficients by least squares from recordings
  dyngen diagnose ROBOT.yaml --params P.yaml --data a.csv [--holdout b.csv]
                                       where the measured-model gap lies and which effect explains it

Run `dyngen COMMAND --help` for a command's options. The YAML schema and the parameter
conventions are in docs/conventions.md; examples/ has the KUKA LWR IV+ and other arms.
"""


def _generate_parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog, description="Derive the regressors and Newton-Euler of an arm symbolically, reduce them to "
        "a minimal set of base coefficients and emit standalone C99 (header, sources, CMakeLists.txt, "
        "manifest.json, coefficients.md) into DIR/<robot name>/.")
    parser.add_argument("robot", metavar="ROBOT.yaml", help="robot description (docs/conventions.md)")
    parser.add_argument("-o", "--output", default="generated", metavar="DIR",
                        help="parent folder of the robot's output folder (default: generated)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    return parser


def _extract_options(parser: argparse.ArgumentParser) -> None:
    from .extraction.options import Options
    from .options import add_arguments

    group = parser.add_argument_group("extraction (defaults: the YAML's `extraction:` block, then these)")
    group.add_argument("--out", default="out", metavar="DIR",
                       help="parent folder of the extraction results OUT/<name>/ (default: out)")
    add_arguments(group, Options)
    group.add_argument("--compare", metavar="FILE",
                       help="a solution (YAML list of links under `solution:`) to compare with, e.g. the paper's")


def _options_from(args, robot):
    from .extraction.options import Options
    from .options import resolve

    return resolve(Options, args, robot.extraction)


def cmd_main(argv, prog="dyngen") -> int:
    """Generate, then extract and export when the YAML has what extraction needs."""
    return _generate_and_extract(argv, prog, required=False, description=(
        "The main job: generate the C model, then, when the YAML has identified coefficients and "
        "parameter bounds, extract consistent link parameters, validate and export them."))


def cmd_extract(argv, prog="dyngen extract") -> int:
    return _generate_and_extract(argv, prog, required=True, description=(
        "Extract physically consistent link parameters from the identified coefficients of ROBOT.yaml "
        "(generating its C model first), validate and export them."))


def _generate_and_extract(argv, prog, required: bool, description: str) -> int:
    parser = _generate_parser(prog)
    parser.description = description
    _extract_options(parser)
    args = parser.parse_args(argv)
    robot = _load(args)
    extracting = required or (bool(robot.identified) and robot.lower is not None)
    if not extracting:
        _generate(args, robot)
        return 0
    _precheck(args, robot)  # bad bounds fail before anything runs or is written
    compare = _compared_solution(args, robot)
    # The model is generated into the per-user cache and copied to -o only once the extraction
    # has succeeded: a failed extraction writes nothing.
    result = _generate(args, robot, out_root=None)
    extraction, options, seconds = _run_extraction(args, result.robot, result.bases, result.folder)
    from .atomic import write_folder

    write_folder(Path(args.output) / robot.name, result.emitted.files)
    _write_extraction(args, result.robot, result.folder, extraction, options, seconds, compare)
    return 0


def _load(args):
    from .description import load_robot

    return load_robot(args.robot)


def _precheck(args, robot) -> None:
    """Bounds that admit no consistent parameters fail here, before anything runs or is written."""
    from .extraction.problem import build_problem

    build_problem(robot, _options_from(args, robot))


def _compared_solution(args, robot):
    """The solution to compare with (--compare or the YAML's extraction.compare), read and checked
    before anything runs: (name, p) or None."""
    from .data.parameters_file import read_link_parameters

    compare = args.compare or robot.extraction.get("compare")
    if not compare:
        return None
    path = Path(compare) if args.compare else Path(args.robot).parent / compare
    return path.name, read_link_parameters(path, robot.dof)


def _run_extraction(args, robot, bases, folder):
    from .extraction.run import extract

    options = _options_from(args, robot)
    progress = Progress(quiet=args.quiet)
    start = time.perf_counter()
    progress.say(f"extracting {robot.name}: {options.procedure}, {options.restarts} restarts, seed {options.seed}")

    def on_progress(stage, done, total):
        progress.update(f"stage {stage}: restart {done}/{total}")

    with progress.step("build and run the NLopt extractor"):
        extraction = extract(robot, bases, folder, options, on_progress)
    return extraction, options, time.perf_counter() - start


def _write_extraction(args, robot, folder, extraction, options, seconds, compare) -> None:
    from .atomic import write_file, write_folder
    from .extraction.driver import standalone_files
    from .extraction import report

    progress = Progress(quiet=args.quiet)
    out = Path(args.out) / robot.name
    write_file(out / "extracted.yaml", report.extracted_yaml(robot, extraction, options, seconds))
    write_folder(out / "extractor", standalone_files(folder))  # the driver as a program of its own
    columns = {"dyngen": extraction.p}
    if compare:
        columns = {compare[0]: compare[1], **columns}
    residual_rows = report.residual_comparison(robot, extraction, columns, folder)
    table = report.consistency_table(columns)
    write_file(out / "consistency.md", table + "\n")
    exported = []
    if not robot.gravity_symbols:  # simulators need a numeric gravity
        from .export import write_all

        exported = write_all(robot, extraction.p, out)
    validation = _validate(robot, folder, extraction, out, progress)
    if not args.quiet:
        print(report.summary(robot, extraction, options, seconds))
        if residual_rows:
            print("  largest coefficient residuals (W pi(p) - pi_hat), dyngen next to the compared solution:")
            print("\n".join("    " + line for line in residual_rows))
        print("  physical consistency per link (lambda_min of tr(I)/2 E - I must be >= 0):")
        print("\n".join("    " + line for line in table.splitlines()))
        print(f"  parameters: {out}/extracted.yaml" + "".join(f", {p}" for p in exported))
        if validation:
            worst = ", ".join(f"{x:.1e}" for x in validation["max_abs"])
            print(f"  Sec. IV validation on the Table V trajectory: max |N-E(extracted) - coefficients model| "
                  f"per joint [Nm]: {worst}")
            print(f"  figures: {validation['paths']['trajectory']}, {validation['paths']['torques']}")


def _validate(robot, folder, extraction, out, progress):
    """The paper's Sec. IV check, for 7-joint arms whose gravity and inertia coefficients were identified."""
    import numpy as np

    from .validation import validate

    targets = extraction.targets
    if robot.dof != 7 or robot.gravity_symbols or not {"gravity", "inertia"} <= set(targets):
        return None
    pi_hat = {}
    for kind in ("gravity", "inertia"):
        W, v = targets[kind].W, targets[kind].v
        if W.shape[0] < W.shape[1] or np.linalg.matrix_rank(W) < W.shape[1]:
            return None  # the identified set does not determine every coefficient
        pi_hat[kind] = np.linalg.lstsq(W, v, rcond=None)[0]
    with progress.step("validate on the Table V trajectory (Sec. IV)"):
        return validate(robot, folder, extraction.p, pi_hat["gravity"], pi_hat["inertia"], out)


def cmd_generate(argv, prog="dyngen generate") -> int:
    args = _generate_parser(prog).parse_args(argv)
    _generate(args, _load(args))
    return 0


def _generate(args, robot, out_root="from args"):
    """Generate into args.output (or, with out_root None, into the per-user cache for now)."""
    from .generate import generate

    progress = Progress(quiet=args.quiet)
    start = time.perf_counter()
    progress.say(f"dyngen {__version__}: generating {args.robot}")
    result = generate(robot, args.output if out_root == "from args" else out_root, progress)
    if not args.quiet:
        _summary(result, Path(args.output) / robot.name, time.perf_counter() - start)
    return result


def _summary(result, destination: Path, seconds: float) -> None:
    robot, bases = result.robot, result.bases
    print(f"{robot.name}: {robot.dof} joints, {robot.convention} DH -> {destination}/ in {seconds:.1f} s")
    print("  base coefficients: " + ", ".join(f"{k} {b.rank}" for k, b in bases.items())
          + f" (of {10 * robot.dof} standard parameters)")
    width = max(len(f.name) for f in result.emitted.functions)
    for f in result.emitted.functions:
        print(f"  {f.name:<{width}}  {f.ops}")
    print(f"  coefficient expressions: {destination}/coefficients.md")


def cmd_identify(argv, prog="dyngen identify") -> int:
    from .measured_cli import cmd_identify as run

    return run(argv, prog)


def cmd_diagnose(argv, prog="dyngen diagnose") -> int:
    from .measured_cli import cmd_diagnose as run

    return run(argv, prog)


COMMANDS = {"generate": cmd_generate, "extract": cmd_extract, "identify": cmd_identify, "diagnose": cmd_diagnose}


def main(argv=None) -> int:
    try:
        return _dispatch(list(sys.argv[1:] if argv is None else argv))
    except (InputError, Infeasible, DriverError) as err:
        print(f"dyngen: error: {_one_line(err)}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. `dyngen ... | head`
        return 0
    except KeyboardInterrupt:
        print("dyngen: interrupted", file=sys.stderr)
        return 130
    except OSError as err:  # e.g. an output folder that cannot be written
        where = f"{err.filename}: " if err.filename else ""
        print(f"dyngen: error: {_one_line(where)}{err.strerror or err}", file=sys.stderr)
        return 2
    except (RecursionError, MemoryError) as err:
        print(f"dyngen: error: the input is too large or nested too deeply ({type(err).__name__})", file=sys.stderr)
        return 2


def _dispatch(argv) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        print(MAIN_HELP, end="")
        return 0 if argv else 2
    if argv[0] == "--version":
        print(f"dyngen {__version__}")
        return 0
    if argv[0] in COMMANDS:
        return COMMANDS[argv[0]](argv[1:], prog=f"dyngen {argv[0]}")
    return cmd_main(argv, prog="dyngen")


def _one_line(err, limit: int = 2000) -> str:
    """Errors quote user input; keep them one bounded line."""
    text = " ".join(str(err).split("\n"))
    return text if len(text) <= limit else text[:limit] + "..."


if __name__ == "__main__":
    sys.exit(main())
