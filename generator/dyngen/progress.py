"""A plain progress display on stderr: each step's name, then its time when it ends."""

from __future__ import annotations

import sys
import time
from contextlib import contextmanager


class Progress:
    def __init__(self, stream=None, quiet: bool = False):
        self.stream = stream or sys.stderr
        self.quiet = quiet
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()

    @contextmanager
    def step(self, what: str):
        start = time.perf_counter()
        if not self.quiet and self.tty:  # a live line only where it can be overwritten
            self.stream.write(f"  {what} ...\r")
            self.stream.flush()
        yield
        if not self.quiet:
            self.stream.write(f"  {what} done ({time.perf_counter() - start:.2f} s)\n")
            self.stream.flush()

    def update(self, text: str):
        """A transient status line (shown on a terminal only)."""
        if not self.quiet and self.tty:
            self.stream.write(f"  {text}\033[K\r")
            self.stream.flush()

    def say(self, text: str):
        if not self.quiet:
            self.stream.write(text + "\n")
            self.stream.flush()
