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
    from ..data.parameters_file import prior_or_nominal, read_link_parameters
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
    prior = prior_or_nominal(options.prior, robot)
    # --- hook (data/trust.py): a recording whose nominal residual exceeds its torque is conditioned again, or
    # nothing is fitted nor written (exit 3)
    from ..data.trust import EXIT_UNUSABLE, Unusable

    windows = {}  # conditioned windows of the recordings read in blocks: the trust and sanity checks' sample
    try:
        signals, select, again = trusted(model, prior, signals, select, lambda x: _sampled(x, robot, args, windows))
    except Unusable as err:
        import sys

        print(f"dyngen identify: {err.line}", file=sys.stderr)
        return EXIT_UNUSABLE
    # ---
    start = time.perf_counter()
    with progress.step("consistent identification (weighted least squares, barrier solver)"):
        result = identify_consistent(robot, model, model.folder, signals, options, select=select)
    seconds = time.perf_counter() - start
    # --- hook (sanity.py): values in their physical ranges, grid edges, the simple model on --select
    from ..identification.sanity import check, table_lines

    sanity, sanity_table, result = check(robot, model, result, _sampled(signals, robot, args, windows),
                                        _sampled(select, robot, args, windows), prior)
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
        fitted = [w for s in signals for w in getattr(s, "warnings", [])]  # with those of data/trust.py
        for w in [*fitted, *(w for w in again if w not in fitted), *sanity]:
            print(f"  warning: {w}")
        print(f"  {seconds:.1f} s; written: {out}, {table}, " + ", ".join(str(p) for p in exported))
    elif sanity or again:
        import sys

        print("\n".join(f"warning: {w}" for w in [*again, *sanity]), file=sys.stderr)
    return 0


def trusted(model, p, signals, select, sampled):
    """(signals, select, warnings): the fit and --select sources with any recording held whole whose nominal
    residual (link parameters p) exceeds its torque conditioned again (data/trust.py: its warnings); one read
    in blocks, which keeps its columns as recorded, is judged on sampled([source]) (its windows). Raises
    trust.Unusable; without p (no prior, no parameters.nominal) nothing is judged."""
    if p is None:
        return signals, select, []
    import numpy as np

    from ..catalogue import STANDARD_FROM_DYNAMIC
    from ..data.trust import checked
    from ..identification.blocks import Source

    groups = [list(signals), list(select or [])]
    held = [x.signals for g in groups for x in g if x.signals is not None]
    said = {id(sig): len(sig.warnings) for sig in held}  # a recording kept as it is may be given a warning
    streamed = [(x.name, sampled([x])) for g in groups for x in g if x.signals is None]
    done = iter(checked(model, model(STANDARD_FROM_DYNAMIC.name, np.asarray(p, dtype=float)), held, "identification",
                        streamed))
    out, again = [], []
    for g in groups:
        out.append([])
        for x in g:
            y = next(done) if x.signals is not None else x.signals
            if y is not x.signals:  # conditioned again: its warning is the last
                x = Source.held(y, x.block_rows)
                again.append(y.warnings[-1])
            elif y is not None and len(y.warnings) > said[id(y)]:  # kept: the link parameters are off
                again += y.warnings[said[id(y)]:]
            out[-1].append(x)
    return out[0], out[1] if select is not None else None, again


def _sampled(sources, robot, args, kept=None):
    """Conditioned signals of the sources for the sanity check: a recording held whole as it is,
    one read in blocks whole within streaming.sample.MAX_ROWS samples, else evenly spread
    windows of it (the ranges and the simple model's comparison on a sample, not every row).
    kept: a dict keeping the windows of a recording read in blocks (id of its Source) for the next call."""
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
        if kept is not None and id(s) in kept:
            out += kept[id(s)]
            continue
        # the windows kept from the parse (recordings.read_sources), else read again
        got = s.sample.windows() if s.sample is not None else windows(s.path, robot.dof, s.bag)
        got = [condition(w, conditioning_of(args)) for w in long_enough(got)]
        out += got
        if kept is not None:
            kept[id(s)] = got
    return out
