"""Command-line numbers with their ranges: argparse types that refuse nan, inf and the absurd
(`--restarts -5`, `--threads 100000000`, `--cutoff nan`) with the option named, as argparse
does for any other bad option value."""

from __future__ import annotations

import argparse
import math


def whole(lowest: int, highest: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text[:40]!r}") from None
        if not lowest <= value <= highest:
            raise argparse.ArgumentTypeError(f"expected {lowest} to {highest}, got {value}")
        return value

    parse.__name__ = "whole number"
    return parse


def real(lowest: float, highest: float, *, above: bool = False):
    """A finite number in [lowest, highest] (or (lowest, highest] with above=True)."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text[:40]!r}") from None
        low_ok = value > lowest if above else value >= lowest
        if not math.isfinite(value) or not low_ok or value > highest:
            raise argparse.ArgumentTypeError(f"expected a number {'above' if above else 'from'} {lowest:g} "
                                             f"{'and at most' if above else 'to'} {highest:g}, got {text[:40]}")
        return value

    parse.__name__ = "number"
    return parse
