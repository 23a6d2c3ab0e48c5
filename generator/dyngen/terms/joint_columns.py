"""The per-joint columns `dyngen identify` fits and the excitation design's information matrix holds,
from their terms: the trajectory is designed for the matrix that is identified."""

from __future__ import annotations

import numpy as np

from .friction import Coulomb, Viscous
from .rotor import Armature, Ripple
from .sensor import Offset

DEFAULT_KINDS = ("coulomb", "viscous", "offset", "armature")  # identify's per-joint columns always in
TERM_OF = {"coulomb": Coulomb, "viscous": Viscous, "offset": Offset, "armature": Armature,
           "ripple_cos": Ripple, "ripple_sin": Ripple}  # each kind's term


def column(kind: str, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, vc: float | None = None) -> np.ndarray:
    """(T,): the column of `kind` for one joint's q, qd, qdd (coulomb at scale vc, unfiltered; ripple:
    the first harmonic)."""
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
