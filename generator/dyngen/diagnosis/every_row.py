"""Every row of the long recordings a diagnosis read as windows (streaming/sample.py), read
again in blocks: the final fit's moments over every fit row, and the held-out figures over
every test row. Each block is one roles.Segment; the blocks' sums are added in block order on
both cores (forked.in_order), so they equal one process's sums bitwise."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np

from ..catalogue import RNEA
from ..forked import in_order
from ..terms.context import Memo
from . import fit, joints, reidentify, roles
from . import moments as dz
from .judge import held_sums, over_every_row


def streams_of(segments) -> list:
    """The long recordings (streaming.gap.GapTask) whose windows (streaming/sample.py) the segments
    are, where the windows kept their columns as recorded (data/trust.py may have filtered them since)."""
    tasks = [getattr(getattr(seg.signals, "source", None), "stream", None) if seg.signals.lowpass is None else None
             for seg in segments]
    return [task for k, task in enumerate(tasks) if task is not None and task not in tasks[:k]]


def every_row(context, chosen, tasks, size: int) -> dz.Moments:
    """The fit moments (size slots) of the chosen candidates over every row of the recordings
    `tasks`, read again in blocks (blocks_of): each block's nominal residual and the chosen
    effects' columns at the windows' settings and ranges, on both cores (forked.in_order:
    the blocks' moments added in block order, as one process adds them)."""
    effects = list({c.effect.key: c.effect for c in chosen}.values())
    world = dz.as_chosen(context, chosen)
    n = len(context.robot.joints)

    def of_block(block) -> dz.Moments:
        seg = block_segment(context, block, "fit")
        columns = dz.effect_columns(effects, replace(world, cache=Memo()), seg)  # a memo per block, not kept
        out = dz.empty(n, size)
        for j in range(n):
            acting = [c for c in chosen if c.joint is None or c.joint == j]
            A, slots = dz.joint_matrix(acting, columns, j) if acting else (np.zeros((seg.residual.shape[0], 0)),
                                                                           np.zeros(0, dtype=int))
            dz.accumulate(out, A, slots, seg.residual[:, j], j)
        out.count = seg.residual.shape[0]
        return out

    total = dz.empty(n, size)
    for part in in_order(of_block, blocks_of(tasks)):  # a slot a block does not touch adds an exact zero
        total.G += part.G
        total.b += part.b
        total.c += part.c
        total.count += part.count
    return total


def every_test_row(model, final, modes, completed, judged, segments):
    """The held-out figures over every row of the long test recordings whose windows were judged
    (judge.over_every_row), each block corrected as apply corrected the windows; the other test
    segments as they were. Without such recordings, judged as it is."""
    held = [seg for seg in segments if seg.test.any()]
    streams = streams_of([seg for seg in held if not (seg.fit.any() or seg.select.any())])
    if not streams:
        return judged
    kept = [seg for seg in held if getattr(getattr(seg.signals, "source", None), "stream", None) not in streams]
    chosen, x = final.chosen, final.fit.x

    def of_block(block):
        seg = block_segment(final.context, block, "test")
        context = replace(final.context, cache=Memo())  # a memo per block, not kept
        (effects,) = fit.corrected(context, chosen, x, [seg])
        consistent = None if final.reidentified is None else reidentify.corrections(final.reidentified, model,
                                                                                     [effects])
        (seg,), _ = joints.apply(context, [effects], chosen, x, final.simple, modes, consistent, completed)
        return held_sums(seg, effects.correction, final.simple)

    own = [held_sums(seg, fit.predict(final.context, chosen, x, seg) if chosen else np.zeros_like(seg.residual),
                     final.simple) for seg in kept]
    return over_every_row(judged, itertools.chain(own, in_order(of_block, blocks_of(streams))))


def blocks_of(tasks):
    """Every row of the recordings `tasks` (streaming.gap.GapTask or alike: path, dof, rows,
    bag; a streaming.sample.Rows' span: those rows only), read in blocks, repeated rows left out as conditioning does. Only recordings
    whose blocks are conditioned on their own are marked so (qd and qdd recorded, no filter); a
    law that reads earlier samples (a time shift) starts each block afresh."""
    from ..data.chunks import chunks
    from ..data.log_quality import Streamed
    from ..streaming.sample import _part

    for task in tasks:
        blocks = Streamed().blocks(chunks(task.path, task.dof, True, (), task.rows, task.bag))
        span = getattr(task, "span", None)
        for block in blocks if span is None else (_part(b, (b.t >= span[0]) & (b.t < span[1])) for b in blocks):
            if block.t.size:
                yield block


def block_segment(context, block, role: str):
    """roles.Segment of one block (blocks_of) with its nominal residual, all its samples in `role`."""
    from ..data.conditioning import Signals

    signals = Signals(block.name, block.t, block.q, block.qd, block.qdd, block.tau, block.extra)
    tau_model = context.model.batch(RNEA.name, signals.q, signals.qd, signals.qdd, context.s)
    every = np.ones(block.t.size, dtype=bool)
    masks = {name: every if name == role else ~every for name in ("fit", "select", "test")}
    return roles.Segment(signals, tau_model, signals.tau - tau_model, **masks)
