"""`dyngen identify --ols` (and --kind gravity, inertia): base coefficients by least squares,
accumulated recording by recording in blocks (dyngen.streaming: memory independent of the
recordings' length), the recordings in parallel; with several recordings, each one's residual
under the pooled fit and under its own, and which recordings stand out."""

from __future__ import annotations

from pathlib import Path

from ..errors import printable
from .recordings import check_headers, compiled_model, conditioning_of, conditioning_text


def run_least_squares(args, robot, kind, required, progress, out: Path) -> int:
    """`out`: the YAML to write, already checked against the output-path policy (identify.py)."""
    from ..atomic import write_file
    from ..identification import identified_yaml, summary_table
    from ..identification.samples import stacked_inertia_columns
    from ..streaming.pooled import identify_recordings, table
    from ..streaming.step import Task

    check_headers(args.data, robot, args, kind != "inertia", required)
    progress.say(f"dyngen identify: {robot.name}, {kind} coefficients from {len(args.data)} recording(s)")
    model = compiled_model(args, robot, progress)
    if kind == "inertia":
        assert stacked_inertia_columns(model.manifest) == list(required)
    names = [e["standard"] for e in model.manifest["coefficients"][kind]["expressions"]]
    tasks = [Task(str(p), robot.dof, kind, str(model.folder), conditioning_of(args), required, args.effort_topic)
             for p in args.data]
    with progress.step(f"least squares, {len(tasks)} recording(s) in blocks"):
        result = identify_recordings(tasks, names, args.workers, args.scheduler)
    estimate = result.estimate
    lines = []
    if len(tasks) > 1:
        rows = required if kind == "inertia" else [f"J{j + 1}" for j in range(robot.dof)]
        lines = table(result, list(rows))
        write_file(out.with_suffix(".recordings.md"), f"# {robot.name}: {kind} coefficients, per recording\n\n    "
                   + "\n    ".join(lines) + "\n")
    write_file(out, identified_yaml(robot.name, {kind: estimate}, [printable(s.name) for s in result.sums],
                                    conditioning_text(result.sums)))
    if not args.quiet:
        print(f"{robot.name}: {len(estimate.names)} {kind} coefficients from {estimate.rows} equations; "
              f"condition number {estimate.condition:.3g} (columns scaled {estimate.scaled_condition:.3g}); "
              f"residual RMS {estimate.residual_rms:.4g}")
        print("\n".join("  " + line for line in summary_table(kind, estimate).splitlines()))
        print("\n".join("  " + line for line in lines))
        for w in [*estimate.warnings(), *(w for s in result.sums for w in s.warnings)]:
            print(f"  warning: {w}")
        written = [str(out)] + ([str(out.with_suffix(".recordings.md"))] if lines else [])
        print(f"  written: {', '.join(written)}")
    return 0
