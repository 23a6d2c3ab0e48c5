"""One long recording cut into contiguous pieces in time (e.g. fit, select, test), each to be
conditioned on its own: a filter run over the whole recording would carry samples of one piece
into its neighbour, so the roles would share data at every cut."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .recording import Recording


def parse_fractions(text: str, count: int = 3) -> tuple[float, ...]:
    try:
        parts = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise InputError("--split", "", f"{text!r}: expected {count} fractions such as 0.6,0.2,0.2") from None
    if len(parts) != count or any(not np.isfinite(x) or x < 0 for x in parts) or not 0.99 < sum(parts) < 1.01:
        raise InputError("--split", "", f"{text!r}: expected {count} non-negative fractions summing to 1")
    return parts


def split_recording(r: Recording, fractions) -> list[Recording | None]:
    """One piece per fraction, in time order (None for a fraction of 0)."""
    edges = np.concatenate([[0.0], np.cumsum(fractions)])
    edges[-1] = 1.0
    span = r.t[-1] - r.t[0]
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        if b <= a:
            out.append(None)
            continue
        k = (r.t >= r.t[0] + a * span) & ((r.t < r.t[0] + b * span) if b < 1.0 else True)
        if k.sum() < 8:
            raise InputError(r.name, "--split", f"the piece {a:.0%}-{b:.0%} has {int(k.sum())} samples")

        def cut(x):
            return None if x is None else x[k]

        out.append(Recording(f"{r.name} [{a:.0%}-{b:.0%}]", r.t[k], r.q[k], cut(r.tau), cut(r.qd), cut(r.qdd),
                             {name: v[k] for name, v in r.extra.items()}))
    return out
