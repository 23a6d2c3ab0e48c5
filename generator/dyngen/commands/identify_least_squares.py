"""`dyngen identify --ols` (and --kind gravity, inertia): base coefficients by least squares,
accumulated recording by recording in blocks (dyngen.streaming: memory independent of the
recordings' length), the recordings in parallel; with several recordings, each one's residual
under the pooled fit and under its own, and which recordings stand out."""

from __future__ import annotations

from pathlib import Path

from ..errors import printable
from .recordings import bag_of, check_headers, compiled_model, conditioning_of, conditioning_text


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
    tasks = [Task(str(p), robot.dof, kind, str(model.folder), conditioning_of(args), required, bag_of(args, robot))
             for p in args.data]
    # --- hook (data/trust.py): a recording whose nominal residual exceeds its torque is conditioned again, or
    # nothing is fitted nor written (exit 3)
    from ..data.trust import EXIT_UNUSABLE, Unusable

    try:
        tasks, again = _trusted(args, robot, model, tasks)
    except Unusable as err:
        import sys

        print(f"dyngen identify: {err.line}", file=sys.stderr)
        return EXIT_UNUSABLE
    # ---
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
        for w in [*estimate.warnings(), *(w for s in result.sums for w in s.warnings), *again]:
            print(f"  warning: {w}")
        written = [str(out)] + ([str(out.with_suffix(".recordings.md"))] if lines else [])
        print(f"  written: {', '.join(written)}")
    elif again:
        import sys

        print("\n".join(f"warning: {w}" for w in again), file=sys.stderr)
    return 0


def _trusted(args, robot, model, tasks):
    """(tasks, warnings): data/trust.py's check of every recording against the prior (--prior, else the
    YAML's parameters.nominal; with neither, or for kind inertia, nothing is judged), on its windows
    conditioned as the least squares conditions it; a recording conditioned again there is fitted so.
    Raises trust.Unusable."""
    import dataclasses

    from ..catalogue import STANDARD_FROM_DYNAMIC
    from ..data import condition
    from ..data.parameters_file import prior_or_nominal, read_link_parameters
    from ..data.trust import checked
    from ..streaming.sample import windows
    from .recordings import long_enough

    prior = prior_or_nominal(read_link_parameters(args.prior, robot.dof) if getattr(args, "prior", None) else None,
                             robot)
    if prior is None or tasks[0].kind == "inertia":
        return tasks, []
    pieces = [[condition(w, task.conditioning) for w in long_enough(windows(task.path, task.dof, task.bag))]
              for task in tasks]
    said = {id(w): len(w.warnings) for group in pieces for w in group}
    done = iter(checked(model, model(STANDARD_FROM_DYNAMIC.name, prior),
                        [w for group in pieces for w in group], "identification"))
    out, warnings = [], []
    for task, group in zip(tasks, pieces):
        judged = [next(done) for _ in group]
        for before, after in zip(group, judged):  # conditioned again: its warning is the last; kept: any new one
            warnings += after.warnings[-1:] if after is not before else after.warnings[said[id(after)]:]
        again = next((after for before, after in zip(group, judged) if after is not before), None)
        out.append(task if again is None else dataclasses.replace(task, conditioning=again.options))
    return out, list(dict.fromkeys(warnings))
