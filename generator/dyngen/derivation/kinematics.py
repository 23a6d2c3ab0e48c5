"""Denavit-Hartenberg geometry of one joint, in the form the recursion needs.

standard (classical): T(i-1,i) = Rz(theta) Tz(d) Tx(a) Rx(alpha); joint i turns about z(i-1).
modified (Craig):     T(i-1,i) = Rx(alpha) Tx(a) Rz(theta) Tz(d); joint i turns about z(i).
A revolute joint adds q to theta, a prismatic one adds q to d.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..description import Joint


@dataclass(frozen=True)
class JointGeometry:
    R: sp.Matrix  # rotation of frame i in frame i-1
    offset: list  # standard: O(i-1)->O(i) in frame i; modified: O(i-1)->O(i) in frame i-1
    axis: list  # joint axis in frame i (unit vector)


def rot_x(cos_a, sin_a) -> sp.Matrix:
    return sp.Matrix([[1, 0, 0], [0, cos_a, -sin_a], [0, sin_a, cos_a]])


def rot_z(cos_t, sin_t) -> sp.Matrix:
    return sp.Matrix([[cos_t, -sin_t, 0], [sin_t, cos_t, 0], [0, 0, 1]])


def joint_geometry(convention: str, joint: Joint, cos_t, sin_t, d) -> JointGeometry:
    """cos_t, sin_t: of the full angle theta (q + offset for revolute); d: full offset."""
    ca, sa = sp.cos(joint.alpha), sp.sin(joint.alpha)
    a = joint.a
    if convention == "standard":
        return JointGeometry(R=rot_z(cos_t, sin_t) * rot_x(ca, sa), offset=[a, d * sa, d * ca], axis=[0, sa, ca])
    return JointGeometry(R=rot_x(ca, sa) * rot_z(cos_t, sin_t), offset=[a, -d * sa, d * ca], axis=[0, 0, 1])


def transform(convention: str, joint: Joint, q) -> sp.Matrix:
    """The 4x4 homogeneous T(i-1,i) for a numeric or symbolic q (used by tests and export)."""
    theta = joint.theta + q if joint.revolute else joint.theta
    d = joint.d if joint.revolute else joint.d + q
    g = joint_geometry(convention, joint, sp.cos(theta), sp.sin(theta), d)
    if convention == "standard":
        position = g.R * sp.Matrix(g.offset)
    else:
        position = sp.Matrix(g.offset)
    T = sp.eye(4)
    T[:3, :3] = g.R
    T[:3, 3] = position
    return T
