"""The per-joint columns `dyngen identify` fits by default and the excitation design's
information matrix holds (identification/columns.py, excitation/design.py): one definition of
each, from its term, so the matrix the trajectory is designed for is the one identified.

    column(kind, q, qd, qdd, vc)   (T,) of joint j's own motion (q, qd, qdd: that joint's)
"""

from __future__ import annotations

import numpy as np

from .friction import Coulomb, Viscous
from .rotor import Armature, Ripple
from .sensor import Offset

DEFAULT_KINDS = ("coulomb", "viscous", "offset", "armature")  # identify's per-joint columns always in
TERM_OF = {"coulomb": Coulomb, "viscous": Viscous, "offset": Offset, "armature": Armature,
           "ripple_cos": Ripple, "ripple_sin": Ripple}  # each kind's term


def column(kind: str, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, vc: float | None = None) -> np.ndarray:
    """(T,): the column of `kind` in its joint's rows (coulomb: at velocity scale vc, unfiltered;
    ripple_cos, ripple_sin: the first harmonic of the position)."""
    if kind == "coulomb":
        return Coulomb.regressor(qd, vc)[:, 0]
    if kind == "viscous":
        return Viscous.regressor(qd)[:, 0]
    if kind == "offset":
        return Offset.regressor(qd.shape)[:, 0]
    if kind == "armature":
        return Armature.regressor(qdd)[:, 0]
    if kind in ("ripple_cos", "ripple_sin"):
        return Ripple.harmonic(q, 1, kind[-3:])
    raise ValueError(kind)
