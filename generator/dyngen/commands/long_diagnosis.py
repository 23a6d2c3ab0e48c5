"""`dyngen diagnose` on recordings longer than the diagnosis should hold (--max-rows): each
such --data recording read once in blocks, diagnosed on evenly spread windows of it, its gap
and simple model over every row reported beside (dyngen.streaming.sample). Recordings within
the bound are read whole, as before: the diagnosis is the in-memory one."""

from __future__ import annotations

import numpy as np

from .recordings import bag_of, conditioned, conditioning_of, long_enough


def read_fit(paths, robot, args, model, p, max_rows: int) -> tuple[list, list]:
    """(the fit signals in the order of `paths`, the sampled recordings' summaries for the report)."""
    from ..data import read_recording
    from ..streaming.gap import GapTask
    from ..streaming.sample import sample

    recordings, sampled = [], []
    for path in paths:
        task = GapTask(str(path), robot.dof, str(model.folder), tuple(float(v) for v in p), conditioning_of(args),
                       bag_of(args, robot))
        got = sample(task, max_rows)
        if not got.sampled:  # the whole-file reader and its checks, as before
            recordings.append(read_recording(path, robot.dof, True, (), bag_of(args, robot)))
            continue
        windows = long_enough(got.recordings)
        recordings += windows
        sampled.append(summary(got, windows))
    return conditioned(recordings, args), sampled


def read_windows(paths, robot, args, max_rows: int) -> list:
    """--select and --test recordings, read in blocks: whole within max_rows samples, else
    evenly spread windows of them (streaming/sample.py: those of --test judged over every row,
    diagnosis/pipeline.py); conditioned, each on its own."""
    from ..streaming.sample import windows

    recordings = []
    for path in paths:
        got = windows(path, robot.dof, bag_of(args, robot), max_rows, conditioning=conditioning_of(args))
        recordings += got if len(got) == 1 else long_enough(got)
    return conditioned(recordings, args)


def read_split(paths, robot, args, fractions, max_rows: int) -> tuple[list, list, list]:
    """--split: every --data recording cut in time into fit, select and test (data/split.py's
    edges), read in blocks twice (its time span, then the pieces); each piece whole within
    max_rows samples, else evenly spread windows of it. (fit, select, test) conditioned."""
    from ..data import condition
    from ..data.chunks import chunks
    from ..errors import InputError
    from ..streaming.sample import Rows, Spread, _part
    from ..streaming.step import _local

    roles = ([], [], [])
    edges = np.concatenate([[0.0], np.cumsum(fractions)])
    edges[-1] = 1.0
    for path in paths:
        t0, t1, first = None, None, None
        for block in chunks(path, robot.dof, True, (), 8192, bag_of(args, robot)):
            t0, t1, name, first = block.t[0] if t0 is None else t0, block.t[-1], block.name, first or block
        spreads = [Spread(max_rows) if b > a else None for a, b in zip(edges[:-1], edges[1:])]
        for block in chunks(path, robot.dof, True, (), 8192, bag_of(args, robot)):
            for k, spread in enumerate(spreads):
                if spread is not None:
                    keep = (block.t >= t0 + edges[k] * (t1 - t0)) & (
                        (block.t < t0 + edges[k + 1] * (t1 - t0)) if edges[k + 1] < 1.0 else True)
                    spread.add(_part(block, keep))
        for k, spread in enumerate(spreads):
            if spread is None:
                continue
            if spread.rows < 8:
                raise InputError(name, "--split", f"the piece {edges[k]:.0%}-{edges[k + 1]:.0%} has {spread.rows} samples")
            got = spread.windows(f"{name} [{edges[k]:.0%}-{edges[k + 1]:.0%}]")
            if k == 2 and len(got) > 1 and _local(first, conditioning_of(args)):  # judged over every row
                span = (t0 + edges[k] * (t1 - t0), t0 + edges[k + 1] * (t1 - t0) if edges[k + 1] < 1.0 else np.inf)
                for w in got:
                    w.stream = Rows(str(path), robot.dof, bag_of(args, robot), span=span)
            roles[k].extend(got if len(got) == 1 else long_enough(got))
    return tuple([condition(r, conditioning_of(args)) for r in role] for role in roles)


def summary(got, windows) -> dict:
    from ..streaming.gap import _rms, _solve

    g = got.gap
    simple = np.array([_solve(R) for R in g.factors])
    return {"recording": g.name, "rows": got.rows, "seconds": round(got.seconds, 3),
            "windows": len(windows), "rows_diagnosed": int(sum(w.t.size for w in windows)),
            "gap_rms": np.sqrt(g.squares / g.rows).tolist(), "gap_mean": (g.total / g.rows).tolist(),
            "simple_model": simple.tolist(),
            "simple_rms": [_rms(R, x, g.rows) for R, x in zip(g.factors, simple)],
            "streamed": g.streamed}


def markdown(sampled: list) -> str:
    """The report's section on the sampled recordings."""
    lines = ["", "## Long recordings: diagnosed on a sample", ""]
    for s in sampled:
        n = len(s["gap_rms"])
        lines += [f"{s['recording']}: {s['rows']} samples ({s['seconds']:.0f} s); the diagnosis above ran on "
                  f"{s['windows']} windows spread evenly over it ({s['rows_diagnosed']} samples). Over every "
                  "sample (read in blocks):", "",
                  "| | " + " | ".join(f"J{j + 1}" for j in range(n)) + " |",
                  "|---|" + "---|" * n,
                  "| gap RMS [Nm] | " + " | ".join(f"{x:.3g}" for x in s["gap_rms"]) + " |",
                  "| gap mean [Nm] | " + " | ".join(f"{x:+.3g}" for x in s["gap_mean"]) + " |",
                  "| after the simple model [Nm] | " + " | ".join(f"{x:.3g}" for x in s["simple_rms"]) + " |",
                  ""]
    return "\n".join(lines)
