"""The `dyngen` command."""

from __future__ import annotations

import argparse
import sys
import time

from . import __version__
from .errors import InputError
from .progress import Progress

MAIN_HELP = """\
dyngen: robot dynamic models as exact, standalone C from a DH table.

  dyngen ROBOT.yaml [-o DIR]          the main job: generate (see below)
  dyngen generate ROBOT.yaml [-o DIR] derive, reduce to base coefficients, emit C into DIR/<name>/

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


def cmd_generate(argv, prog="dyngen generate") -> int:
    from .description import load_robot
    from .generate import generate

    args = _generate_parser(prog).parse_args(argv)
    progress = Progress(quiet=args.quiet)
    start = time.perf_counter()
    robot = load_robot(args.robot)  # validate before announcing anything
    progress.say(f"dyngen {__version__}: generating {args.robot}")
    result = generate(robot, args.output, progress)
    if not args.quiet:
        _summary(result, time.perf_counter() - start)
    return 0


def _summary(result, seconds: float) -> None:
    robot, bases = result.robot, result.bases
    print(f"{robot.name}: {robot.dof} joints, {robot.convention} DH -> {result.folder}/ in {seconds:.1f} s")
    print("  base coefficients: " + ", ".join(f"{k} {b.rank}" for k, b in bases.items())
          + f" (of {10 * robot.dof} standard parameters)")
    width = max(len(f.name) for f in result.emitted.functions)
    for f in result.emitted.functions:
        print(f"  {f.name:<{width}}  {f.ops}")
    print(f"  coefficient expressions: {result.folder}/coefficients.md")


COMMANDS = {"generate": cmd_generate}


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help"):
        print(MAIN_HELP, end="")
        return 0 if argv else 2
    if argv[0] == "--version":
        print(f"dyngen {__version__}")
        return 0
    try:
        if argv[0] in COMMANDS:
            return COMMANDS[argv[0]](argv[1:], prog=f"dyngen {argv[0]}")
        return cmd_generate(argv, prog="dyngen")  # the main job
    except InputError as err:
        print(f"dyngen: error: {err}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. `dyngen ... | head`
        return 0
    except KeyboardInterrupt:
        print("dyngen: interrupted; nothing was written", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
