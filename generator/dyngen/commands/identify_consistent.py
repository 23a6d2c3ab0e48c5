"""`dyngen identify` (kind full): the run of the physically consistent identification (its
options: identification.consistent.ConsistentOptions, flags by commands/identify.py)."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from ..options import resolve


def run_consistent(args, robot, model, signals, progress, out: Path) -> int:
    """signals: identification.blocks.Source of every --data recording (commands/recordings.py); `out`: the
    YAML to write, already checked against the output-path policy (identify.py)."""
    from ..atomic import write_file
    from ..data.parameters_file import read_link_parameters
    from ..export import write_all
    from ..identification.consistent import ConsistentOptions, identify_consistent
    from ..identification.consistent_output import consistent_table, consistent_yaml, summary_lines
    from .recordings import conditioning_text, read_sources

    options = resolve(ConsistentOptions, args, {})
    if "none" in options.candidates:  # names were checked by the parser (dyngen.options)
        options = replace(options, candidates=())
    if args.prior:
        options = replace(options, prior=read_link_parameters(args.prior, robot.dof))
    select = read_sources(args.select, robot, args) if args.select else None
    start = time.perf_counter()
    with progress.step("consistent identification (weighted least squares, barrier solver)"):
        result = identify_consistent(robot, model, model.folder, signals, options, select=select)
    seconds = time.perf_counter() - start
    # --- hook (sanity.py): values in their physical ranges, grid edges, the simple model on --select
    import numpy as np

    from ..identification.sanity import check, table_lines

    prior = options.prior if options.prior is not None else (
        np.array([v for link in robot.nominal for v in link.as_tuple()]) if robot.nominal is not None else None)
    sanity, sanity_table, result = check(robot, model, result, _sampled(signals, robot, args),
                                        _sampled(select, robot, args), prior)
    # ---
    sources = [s.name for s in signals]  # printable: data/recording.py
    write_file(out, consistent_yaml(robot, result, sources, conditioning_text(signals)))
    table = out.with_suffix(".md")
    write_file(table, f"# {robot.name}: consistent identification from {', '.join(sources)}\n\n"
               + "\n".join(summary_lines(robot, result)) + "\n\n" + consistent_table(result) + "\n\n"
               + "\n".join(["## Sanity", ""] + [f"- warning: {w}" for w in sanity] + [""] + table_lines(sanity_table))
               + "\n")
    exported = write_all(robot, result.p, out.parent, result.joint_dynamics())
    if not args.quiet:
        print("\n".join(summary_lines(robot, result)))
        for w in [*(w for s in signals for w in getattr(s, "warnings", [])), *sanity]:
            print(f"  warning: {w}")
        print(f"  {seconds:.1f} s; written: {out}, {table}, " + ", ".join(str(p) for p in exported))
    elif sanity:
        import sys

        print("\n".join(f"warning: {w}" for w in sanity), file=sys.stderr)
    return 0


def _sampled(sources, robot, args):
    """Conditioned signals of the sources for the sanity check: a recording held whole as it is,
    one read in blocks whole within streaming.sample.MAX_ROWS samples, else evenly spread
    windows of it (the ranges and the simple model's comparison on a sample, not every row)."""
    from ..data import condition
    from ..streaming.sample import windows
    from .recordings import conditioning_of, long_enough

    if sources is None:
        return None
    out = []
    for s in sources:
        if s.signals is not None:
            out.append(s.signals)
            continue
        # the windows kept from the parse (recordings.read_sources), else read again
        got = s.sample.windows() if s.sample is not None else windows(s.path, robot.dof, s.effort_topic)
        out += [condition(w, conditioning_of(args)) for w in long_enough(got)]
    return out
