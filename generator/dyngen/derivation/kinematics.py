"""Each joint model (description/joint_model.py) in the form the recursion needs.

The recursion crosses joint i at a point X fixed in link i-1 (for a revolute joint on its axis,
so that X moves with link i-1 and with link i alike): it moves link i-1's acceleration from
O(i-1) to X (`before`, in frame i-1), turns into frame i, adds the joint's motion and moves on
from X to O(i) (`after`, in frame i). X is the joint frame's origin. A prismatic joint's slide
is carried on the side that already has a translation (the link frame's when the placement has
none, as in standard DH), so that at most one of the two moves is not zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..description.joint_model import JointModel, rot_z
from .program import add, mat_t_vec, mat_vec

ZERO = [sp.Integer(0)] * 3


@dataclass(frozen=True)
class JointGeometry:
    R: sp.Matrix  # rotation of link frame i in frame i-1
    before: list  # O(i-1) -> X, in frame i-1
    after: list  # X -> O(i), in frame i
    spin: list  # joint axis in frame i for a revolute joint, else zero
    slide: list  # joint axis in frame i for a prismatic joint, else zero

    @property
    def revolute(self) -> bool:
        return any(x != 0 for x in self.spin)


def joint_geometry(model: JointModel, cos_t, sin_t, coordinate) -> JointGeometry:
    """cos_t, sin_t: of a revolute joint's full angle (q + offset); coordinate: a prismatic
    joint's full length (q + offset), else unused."""
    place, frame = model.placement, model.frame
    axis = list(frame.R.row(2))  # z of J_i in frame i: the third row of frame.R
    if model.revolute:
        R = place.R * rot_z(cos_t, sin_t) * frame.R
        slide, spin, moved = ZERO, axis, ZERO
    else:
        R = place.R * frame.R
        slide, spin, moved = axis, ZERO, [0, 0, coordinate]
    if place.moves:
        before, after = add(list(place.p), mat_vec(place.R, moved)), mat_t_vec(frame.R, list(frame.p))
    else:
        before, after = ZERO, mat_t_vec(frame.R, add(moved, list(frame.p)))
    return JointGeometry(R=R, before=before, after=after, spin=spin, slide=slide)
