"""The options of `dyngen identify`: which coefficients and by which method (Options), and those of
the consistent identification (ConsistentOptions, consistent.py), with the grids it searches."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..arguments import real
from ..description.extraction_options import Options as ExtractOptions
from ..options import option
from ..terms.friction import SCALE_GRID
from ..terms.joint_columns import DEFAULT_KINDS

KINDS = ("full", "gravity", "inertia")


@dataclass(frozen=True)
class Options:
    kind: str = option("full", "which coefficients", choices=KINDS)
    ols: bool = option(False, "plain least squares of the base coefficients instead (no friction, no consistency)")
    consistent: bool = option(False, "the consistent identification (the default for --kind full; kept for scripts)")


CHOICES = ("coulomb", "viscous", "offset", "armature", "ripple")  # what options.friction may name
CANDIDATES = ("ripple", "tilt", "falling")  # optional groups, decided on held-out data
BOUNDS = ("viscous", "dissipative")
SMOOTHING_GRID = SCALE_GRID  # rad/s, candidates for vs_j
LAG_GRID = (0.0, 0.01, 0.02, 0.04)  # s, candidates for the Coulomb term's lag behind the velocity
REGULARISATION_GRID = (0.0, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0)


@dataclass
class ConsistentOptions:
    """The consistent identification's options: with option(...), also `dyngen identify` flags."""

    friction: tuple = option(DEFAULT_KINDS, "per-joint columns always in: " + ", ".join(CHOICES)
                             + " (ripple: cos q_j, sin q_j)", metavar="LIST", listed=True, choices=CHOICES)
    candidates: tuple = option(CANDIDATES, "optional parts of the model, each kept only where held-out stretches "
                               "of the fit data ask for it: ripple (cos q_j, sin q_j per joint), tilt (a tilted "
                               "base), falling (friction falling with speed per joint: viscous below 0, still "
                               "opposing motion up to the velocity limit); 'none' for none", metavar="LIST",
                               listed=True, choices=CANDIDATES + ("none",))
    smoothing: float | None = option(None, "Coulomb friction as tanh(qd / V) with this V [rad/s] on every joint "
                                     "(default: chosen per joint on the fit data)", metavar="V",
                                     parse=real(0, 100, above=True))
    margin: float = ExtractOptions.margin  # consistency margin [kg m^2]: the extraction's
    restarts: int = 2
    seed: int = 1
    threads: int = 0
    max_rounds: int = 8  # active-set rounds for the signs of the friction values
    weighted: bool = True  # rows scaled by 1 / sigma_joint
    prior: np.ndarray | None = None  # dynamic parameters (10N); default the YAML's nominal
    regularisation: float | None = option(None, "weight of the prior (default: chosen on held-out data: "
                                          "contiguous parts of the fit data, or --select data)", metavar="L",
                                          parse=real(0, 1e9))  # None: chosen from `grid`
    grid: tuple = REGULARISATION_GRID
    folds: int = 5  # contiguous parts for the choices on held-out data when no select data are given
    rule: str = "1se"  # "1se" (one-standard-error rule) or "min" (the best held-out score)
    tilt: bool | None = option(None, "always fit a tilted base (a rotation of gravity; by default a candidate, "
                               "see --candidates)", const=True)  # True always, False never, None a candidate
    friction_lag: bool = True  # Coulomb term follows the velocity with a per-joint lag from LAG_GRID
    friction_bound: str = "viscous"  # "viscous": Fc, Fv >= 0 but where "falling" is chosen; "dissipative":
    # Fc + Fv v_max >= 0 on every joint (solver.py)
    block_rows: int = 8192  # samples per block of a recording held whole (blocks.py)
    workers: int = 0  # driver runs at once in the cross-validation (0: up to 2, as the cores allow)
