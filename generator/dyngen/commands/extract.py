"""`dyngen extract` and the main job: generate, then extract consistent link parameters, write,
validate and export them (the extraction step, dyngen.extraction.run)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from ..progress import Progress
from . import generate


def _extract_options(parser: argparse.ArgumentParser) -> None:
    from ..description.extraction_options import Options
    from ..options import add_arguments

    group = parser.add_argument_group("extraction (defaults: the YAML's `extraction:` block, then these)")
    group.add_argument("--out", default="out", metavar="DIR",
                       help="parent folder of the extraction results OUT/<name>/ (default: out)")
    add_arguments(group, Options)
    group.add_argument("--compare", metavar="FILE",
                       help="a solution (YAML list of links under `solution:`) to compare with, e.g. the paper's")


def _options_from(args, robot):
    from ..description.extraction_options import Options
    from ..options import resolve

    return resolve(Options, args, robot.extraction)


def main_job(argv, prog="dyngen") -> int:
    """Generate, then extract and export when the YAML has what extraction needs."""
    return _generate_and_extract(argv, prog, required=False, description=(
        "The main job: generate the C model, then, when the YAML has identified coefficients and "
        "parameter bounds, extract consistent link parameters, validate and export them."))


def main(argv, prog="dyngen extract") -> int:
    return _generate_and_extract(argv, prog, required=True, description=(
        "Extract physically consistent link parameters from the identified coefficients of ROBOT.yaml "
        "(generating its C model first), validate and export them."))


def _generate_and_extract(argv, prog, required: bool, description: str) -> int:
    parser = generate.parser(prog)
    parser.description = description
    _extract_options(parser)
    args = parser.parse_args(argv)
    robot = generate.load(args)
    extracting = required or (bool(robot.identified) and robot.lower is not None)
    generate.check_output(args, Path(args.output) / robot.name)
    if not extracting:
        generate.generate_step(args, robot)
        return 0
    compare_path = args.compare or robot.extraction.get("compare")
    generate.check_output(args, Path(args.out) / robot.name,
                          [args.compare or (Path(args.robot).parent / compare_path if compare_path else None)])
    _precheck(args, robot)  # bad bounds fail before anything runs or is written
    compare = _compared_solution(args, robot)
    # The model is generated into the per-user cache and copied to -o only once the extraction
    # has succeeded: a failed extraction writes nothing.
    result = generate.generate_step(args, robot, out_root=None)
    extraction, options, seconds = _run_extraction(args, result.robot, result.bases, result.folder)
    from ..atomic import write_folder

    write_folder(Path(args.output) / robot.name, result.emitted.files)
    _write_extraction(args, result.robot, result.folder, extraction, options, seconds, compare)
    return 0


def _precheck(args, robot) -> None:
    """Bounds that admit no consistent parameters fail here, before anything runs or is written."""
    from ..extraction.problem import build_problem

    build_problem(robot, _options_from(args, robot))


def _compared_solution(args, robot):
    """The solution to compare with (--compare or the YAML's extraction.compare), read and checked
    before anything runs: (name, p) or None."""
    from ..data.parameters_file import read_link_parameters

    compare = args.compare or robot.extraction.get("compare")
    if not compare:
        return None
    path = Path(compare) if args.compare else Path(args.robot).parent / compare
    return path.name, read_link_parameters(path, robot.dof)


def _run_extraction(args, robot, bases, folder):
    from ..extraction.run import extract

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
    from ..output_paths import results_folder

    target = Path(args.out) / robot.name
    with results_folder(target) as staging:  # the folder is written as one unit
        _write_results(args, robot, folder, extraction, options, seconds, compare, staging, target)


def _write_results(args, robot, folder, extraction, options, seconds, compare, out, target) -> None:
    from ..atomic import write_file, write_folder
    from ..extraction.driver import standalone_files
    from ..extraction import report
    from ..output_paths import shown

    progress = Progress(quiet=args.quiet)
    write_file(out / "extracted.yaml", report.extracted_yaml(robot, extraction, options, seconds))
    write_folder(out / "extractor", standalone_files(folder))  # the driver as a program of its own
    columns = {"dyngen": extraction.p}
    if compare:
        columns = {compare[0]: compare[1], **columns}
    residual_rows = report.residual_comparison(robot, extraction, columns, folder)
    table = report.consistency_table(columns)
    warnings = "".join(f"**{line}**\n\n" for line in report.unreachable(robot, extraction))
    write_file(out / "consistency.md", warnings + table + "\n")
    exported = []
    if not robot.gravity_symbols:  # simulators need a numeric gravity
        from ..export import write_all

        exported = [shown(p, out, target) for p in write_all(robot, extraction.p, out)]
    validation = _validate(robot, folder, extraction, out, progress)
    if not args.quiet:
        print(report.summary(robot, extraction, options, seconds))
        if residual_rows:
            print("  largest coefficient residuals (W pi(p) - pi_hat), dyngen next to the compared solution:")
            print("\n".join("    " + line for line in residual_rows))
        print("  physical consistency per link (lambda_min of tr(I)/2 E - I must be >= 0):")
        print("\n".join("    " + line for line in table.splitlines()))
        print(f"  parameters: {target}/extracted.yaml" + "".join(f", {p}" for p in exported))
        if validation:
            worst = ", ".join(f"{x:.1e}" for x in validation["max_abs"])
            print(f"  Sec. IV validation on the Table V trajectory: max |N-E(extracted) - coefficients model| "
                  f"per joint [Nm]: {worst}")
            print(f"  figures: {shown(validation['paths']['trajectory'], out, target)}, "
                  f"{shown(validation['paths']['torques'], out, target)}")


def _validate(robot, folder, extraction, out, progress):
    """The paper's Sec. IV check, for 7-joint arms whose gravity and inertia coefficients were identified."""
    import numpy as np

    from ..validation import validate

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
