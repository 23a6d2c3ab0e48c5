"""`dyngen generate`: derive, reduce and emit one arm's C (the generate step, dyngen.generate)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from .. import __version__
from ..errors import printable
from ..progress import Progress


def parser(prog: str) -> argparse.ArgumentParser:
    """The generate options; extract adds its own to them."""
    result = argparse.ArgumentParser(
        prog=prog, description="Derive the regressors and Newton-Euler of an arm symbolically, reduce them to "
        "a minimal set of base coefficients and emit standalone C99 (header, sources, CMakeLists.txt, "
        "manifest.json, coefficients.md) into DIR/<robot name>/.")
    result.add_argument("robot", metavar="ROBOT.yaml", help="robot description: a YAML (docs/conventions.md) "
                        "or a URDF (docs/urdf.md)")
    result.add_argument("--base-link", metavar="NAME", help="URDF: the chain's first link (default: the root)")
    result.add_argument("--tip-link", metavar="NAME", help="URDF: the chain's last link (default: the unique leaf)")
    result.add_argument("--no-snap", action="store_true",
                        help="URDF: keep angles and axes as written (default: snap them to exact values)")
    result.add_argument("-o", "--output", default="generated", metavar="DIR",
                        help="parent folder of the robot's output folder (default: generated)")
    result.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    result.add_argument("--force", action="store_true",
                        help="replace an output folder that holds files dyngen did not write (docs/untrusted-input.md)")
    return result


def main(argv, prog="dyngen generate") -> int:
    args = parser(prog).parse_args(argv)
    robot = load(args)
    check_output(args, Path(args.output) / robot.name)
    generate_step(args, robot)
    return 0


def check_output(args, folder: Path, inputs=()) -> None:
    """The output path policy (dyngen.output_paths), before any work (what it replaces is said at the end)."""
    from ..output_paths import check_folder

    check_folder(folder, [args.robot, *inputs], args.force)


def generate_step(args, robot, out_root="from args"):
    """Generate into args.output (or, with out_root None, into the per-user cache for now)."""
    from ..generate import generate

    progress = Progress(quiet=args.quiet)
    start = time.perf_counter()
    progress.say(f"dyngen {__version__}: generating {printable(args.robot)}")
    result = generate(robot, args.output if out_root == "from args" else out_root, progress)
    if not args.quiet:
        summary(result, Path(args.output) / robot.name, time.perf_counter() - start)
    return result


def summary(result, destination: Path, seconds: float) -> None:
    robot, bases = result.robot, result.bases
    print(f"{robot.name}: {robot.dof} joints, {robot.convention if robot.convention == 'urdf' else robot.convention + ' DH'} -> {destination}/ in {seconds:.1f} s")
    for snap, effect in zip(robot.snaps, robot.snap_effects or [None] * len(robot.snaps)):
        change = f", gravity torques change by at most {effect:.1e}" if effect is not None else ""
        print(f"  snapped {snap.joint} {snap.field}: {snap.before} -> {snap.after}{change} (--no-snap keeps it)")
    for note in robot.notes:
        print(f"  note: {note}")
    print("  base coefficients: " + ", ".join(f"{k} {b.rank}" for k, b in bases.items())
          + f" (of {10 * robot.dof} standard parameters)")
    width = max(len(f.name) for f in result.emitted.functions)
    for f in result.emitted.functions:
        print(f"  {f.name:<{width}}  {f.ops}")
    print(f"  coefficient expressions: {destination}/coefficients.md")




def load(args):
    from ..description import load_description

    urdf = {k: getattr(args, k) for k in ("base_link", "tip_link") if getattr(args, k, None)}
    if getattr(args, "no_snap", False):
        urdf["snap"] = False
    return load_description(args.robot, **urdf)
