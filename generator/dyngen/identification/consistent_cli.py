"""`dyngen identify` (kind full): options and run of the physically consistent identification."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ..arguments import real
from ..errors import InputError


def add_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("physically consistent identification (--kind full, the default)")
    group.add_argument("--ols", action="store_true",
                       help="plain least squares of the base coefficients instead (no friction, no consistency)")
    group.add_argument("--consistent", action="store_true",
                       help="the consistent identification (the default for --kind full; kept for scripts)")
    group.add_argument("--prior", metavar="P.yaml",
                       help="link parameters to regularise toward and to keep what the data do not see near "
                            "(default: the YAML's parameters.nominal)")
    group.add_argument("--regularisation", type=real(0, 1e9), metavar="L",
                       help="weight of the prior (default: chosen by cross-validation over contiguous parts of "
                            "the fit data, or on --select data)")
    group.add_argument("--select", action="append", metavar="CSV",
                       help="recording(s) to choose the regularisation and the --candidates on (never fitted)")
    group.add_argument("--friction", default="coulomb,viscous,offset,armature", metavar="LIST",
                       help="per-joint columns: coulomb, viscous, offset, armature, ripple (cos q_j, sin q_j) "
                            "(default coulomb,viscous,offset,armature)")
    group.add_argument("--tilt", action="store_true",
                       help="always fit a tilted base (a rotation of gravity; by default a candidate, see --candidates)")
    group.add_argument("--candidates", default="ripple,tilt,falling", metavar="LIST",
                       help="optional parts of the model, each kept only where held-out stretches of the fit data "
                            "ask for it: ripple (cos q_j, sin q_j per joint), tilt (a tilted base), falling (friction "
                            "falling with speed per joint: viscous below 0, still opposing motion up to the velocity "
                            "limit); 'none' for none (default ripple,tilt,falling)")
    group.add_argument("--smoothing", type=real(0, 100, above=True), metavar="V",
                       help="Coulomb friction as tanh(qd / V) with this V [rad/s] on every joint (default: chosen "
                            "per joint on the fit data)")


def run_consistent(args, robot, model, signals, progress) -> int:
    from ..atomic import write_file
    from ..data.parameters_file import read_link_parameters
    from ..export import write_all
    from .consistent import ConsistentOptions, identify_consistent
    from .consistent_output import consistent_table, consistent_yaml, summary_lines

    friction = _names("--friction", args.friction, {"coulomb", "viscous", "offset", "armature", "ripple"})
    candidates = () if args.candidates.strip() == "none" else \
        _names("--candidates", args.candidates, {"ripple", "tilt", "falling"})
    if args.regularisation is not None and not args.regularisation >= 0:
        raise InputError("--regularisation", "", f"{args.regularisation} must be >= 0")
    if args.smoothing is not None and not args.smoothing > 0:
        raise InputError("--smoothing", "", f"{args.smoothing} must be > 0")
    prior = read_link_parameters(args.prior, robot.dof) if args.prior else None
    from ..measured_cli import _read

    select = _read(args.select, robot, args) if args.select else None
    options = ConsistentOptions(friction=friction, candidates=candidates, prior=prior,
                                regularisation=args.regularisation, tilt=True if args.tilt else None,
                                smoothing=args.smoothing)
    start = time.perf_counter()
    with progress.step("consistent identification (weighted least squares, barrier solver)"):
        result = identify_consistent(robot, model, model.folder, signals, options, select=select)
    seconds = time.perf_counter() - start
    out = Path(args.output) if args.output else Path("out") / robot.name / "identified_consistent.yaml"
    sources = [Path(p).name for p in args.data]
    from ..measured_cli import _conditioning_text

    write_file(out, consistent_yaml(robot, result, sources, _conditioning_text(signals)))
    table = out.with_suffix(".md")
    write_file(table, f"# {robot.name}: consistent identification from {', '.join(sources)}\n\n"
               + "\n".join(summary_lines(robot, result)) + "\n\n" + consistent_table(result) + "\n")
    exported = write_all(robot, result.p, out.parent, result.joint_dynamics())
    if not args.quiet:
        print("\n".join(summary_lines(robot, result)))
        for w in (w for s in signals for w in getattr(s, "warnings", [])):
            print(f"  warning: {w}")
        print(f"  {seconds:.1f} s; written: {out}, {table}, " + ", ".join(str(p) for p in exported))
    return 0


def _names(flag: str, text: str, known: set) -> tuple:
    names = tuple(x.strip() for x in text.split(",") if x.strip())
    unknown = [x for x in names if x not in known]
    if unknown:
        raise InputError(flag, "", f"unknown name(s) {', '.join(unknown)}; expected some of {', '.join(sorted(known))}")
    return names


def held_out_rms(model, result, signals) -> np.ndarray:
    """RMS per joint of measured minus predicted torque on recordings the fit has not seen."""
    r = np.vstack([s.tau - result.predict(model, s) for s in signals])
    return np.sqrt(np.mean(r ** 2, axis=0))
