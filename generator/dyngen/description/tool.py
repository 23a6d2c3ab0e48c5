"""The flange (tool) frame: an optional fixed offset from the last link frame.

YAML `tool: {xyz: [x, y, z], rpy: [roll, pitch, yaw]}` (both optional, default zero), in the
last link frame, URDF's convention: the tool frame is Trans(xyz) Rz(yaw) Ry(pitch) Rx(roll).
Exact numbers as in the DH table ("pi/2" stays exact, so its zeros drop out of the code); the
sine and cosine of any other angle are written as 40-digit numbers.
"""

from __future__ import annotations

import sympy as sp

from .joint_model import Rigid


def _trig(fn, angle) -> sp.Expr:
    value = fn(angle)
    return value if value.is_Rational else sp.Float(value.evalf(40), 40)


def tool_frame(xyz, rpy) -> Rigid:
    (cr, sr), (cp, sp_), (cy, sy) = ((_trig(sp.cos, a), _trig(sp.sin, a)) for a in rpy)
    Rx = sp.Matrix([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = sp.Matrix([[cp, 0, sp_], [0, 1, 0], [-sp_, 0, cp]])
    Rz = sp.Matrix([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rigid(sp.ImmutableMatrix(Rz * Ry * Rx), sp.ImmutableMatrix(list(xyz)))
