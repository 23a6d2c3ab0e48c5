"""What a term's columns are computed in besides the recording (the model, the robot, its link
parameters, what the chosen terms set) and its memo."""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

# Bytes of columns the memo keeps (beyond, the least recently used go: computed again, the same
# numbers). Unbounded, every refinement trial's columns stayed: 3.7 GB for 5 minutes at 200 Hz.
MEMO_BYTES = 256 << 20


class Memo:
    """compute() once per key, kept within `limit` bytes (least recently used evicted first)."""

    def __init__(self, limit: int | None = None):
        self.limit = MEMO_BYTES if limit is None else limit
        self.values: OrderedDict = OrderedDict()
        self.bytes = 0

    def get(self, key, compute):
        if key in self.values:
            self.values.move_to_end(key)
            return self.values[key]
        value = compute()
        size = _nbytes(value)
        if size <= self.limit:
            self.values[key] = value
            self.bytes += size
            while self.bytes > self.limit:
                _, old = self.values.popitem(last=False)
                self.bytes -= _nbytes(old)
        return value


def _nbytes(value) -> int:
    if isinstance(value, np.ndarray):
        return value.nbytes
    if isinstance(value, (tuple, list)):
        return sum(_nbytes(v) for v in value)
    return 64


@dataclass
class Context:
    """What a term's columns may use besides the signals."""

    model: object  # dyngen.runtime.Compiled
    robot: object  # dyngen.description.Robot
    p: np.ndarray
    s: np.ndarray
    sign_velocity: float  # rad/s (m/s): sign(qd) is smoothed as tanh(qd / sign_velocity) (diagnosis Options)
    q_range: tuple | None = None  # (low, high) per joint: the positions the fit data cover
    # The arm and sensor as the chosen terms have them (moments.as_chosen): other terms' torques
    # measured `delay` s late, the arm's times `scale[j]` on joint j (1 + a sensor gain; None: 1),
    # `load` (m, mx, my, mz) of a payload on the last link, whose gravity a tilt turns too.
    delay: float = 0.0
    scale: tuple | None = None
    load: tuple | None = None
    cache: Memo = field(default_factory=Memo)  # columns and shared intermediates, per recording (memo)

    def memo(self, key, compute):
        """compute() once per key (one diagnosis's recordings do not change, so a value computed again is the same)."""
        return self.cache.get(key, compute)
