"""The options of `dyngen identify` that are not the consistent identification's own
(identification.consistent.ConsistentOptions): which coefficients, and by which method."""

from __future__ import annotations

from dataclasses import dataclass

from ..options import option

KINDS = ("full", "gravity", "inertia")


@dataclass(frozen=True)
class Options:
    kind: str = option("full", "which coefficients", choices=KINDS)
    ols: bool = option(False, "plain least squares of the base coefficients instead (no friction, no consistency)")
    consistent: bool = option(False, "the consistent identification (the default for --kind full; kept for scripts)")
