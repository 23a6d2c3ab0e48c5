"""`dyngen diagnose --survey`: the measured-model gap of every --data recording, each read in
blocks (memory independent of its length) on all cores or a Dask cluster, with the simple model
pooled and per recording, and which recordings stand out (dyngen.streaming.gap). For a plant's
many arms, or one arm's days: survey them all, then diagnose the one that differs."""

from __future__ import annotations

import json
from pathlib import Path

from .recordings import bag_of, check_headers, compiled_model, conditioning_of


def run_survey(args, robot, p, progress) -> int:
    from ..atomic import write_file
    from ..errors import InputError
    from ..streaming.gap import GapTask, survey, table

    if args.select or args.test or args.holdout or args.split:
        raise InputError("--survey", "", "surveys the --data recordings only: give no --select, --test, --holdout "
                         "or --split with it")
    from ..output_paths import check_folder, results_folder

    out = Path(args.out) if args.out else Path("out") / robot.name / "survey"
    check_folder(out, [args.robot, args.params, *args.data, args.model], args.force)  # before any work
    check_headers(args.data, robot, args)
    progress.say(f"dyngen diagnose --survey: {robot.name} with {Path(args.params).name}, {len(args.data)} recording(s)")
    model = compiled_model(args, robot, progress)
    tasks = [GapTask(str(x), robot.dof, str(model.folder), tuple(float(v) for v in p), conditioning_of(args),
                     bag_of(args, robot)) for x in args.data]
    with progress.step(f"gap per recording, {len(tasks)} recording(s) in blocks"):
        result = survey(tasks, args.workers, args.scheduler)
    lines = table(result)
    doc = {"robot": robot.name, "params": Path(args.params).name, "pooled_simple_model": result.simple.tolist(),
           "pooled_rms": result.pooled_rms.tolist(), "pooled_rms_simple": result.pooled_simple.tolist(),
           "recordings": [{"name": g.name, "rows": g.rows, "rms": r.tolist(), "mean": m.tolist(),
                           "rms_simple_pooled": a.tolist(), "rms_simple_own": o.tolist()}
                          for g, r, m, a, o in zip(result.gaps, result.rms, result.mean, result.rms_simple,
                                                   result.rms_own)],
           "differs": [{"name": n, "joints": [j + 1 for j in js]} for n, js in result.differs(1.5)]}
    with results_folder(out) as staging:  # its own folder, written as one unit
        write_file(staging / "recordings.md", f"# {robot.name}: the gap per recording ({Path(args.params).name})"
                   "\n\n    " + "\n    ".join(lines) + "\n")
        write_file(staging / "recordings.json", json.dumps(doc, indent=1) + "\n")
    if not args.quiet:
        print("\n".join("  " + line for line in lines))
        print(f"  written: {out / 'recordings.md'}, {out / 'recordings.json'}")
    return 0
