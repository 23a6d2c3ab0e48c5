"""The joint model: where each joint sits and how it moves (Pinocchio's shape).

Link frame i (where link i's parameters are expressed) in link frame i-1 is

    T(i-1, i)(q) = placement_i * motion_i(q) * frame_i

placement_i  the joint frame J_i in link frame i-1 (fixed; Pinocchio's jointPlacement),
motion_i(q)  Rz(offset + q) for a revolute joint, Tz(offset + q) for a prismatic one: the joint
             turns about, or slides along, the z axis of J_i (Pinocchio's jdata.M()),
frame_i      link frame i in J_i (fixed; the identity when the link frame is the joint frame,
             as in a URDF or Craig's modified DH).

It is built once per description (a DH table fills it, see dh.py; a URDF joint is exactly a
placement and an axis) and read through two faces: exact SymPy matrices for the derivation
and the exporters, and `forward_kinematics`, numpy vectorised over samples.
"""

from __future__ import annotations

import functools

from dataclasses import dataclass

import numpy as np
import sympy as sp

from .angles import cos_sin

REVOLUTE, PRISMATIC = "revolute", "prismatic"


@dataclass(frozen=True)
class Rigid:
    """An exact rigid transform: rotation R (3x3) and translation p (3), x -> R x + p."""

    R: sp.ImmutableMatrix
    p: sp.ImmutableMatrix

    @staticmethod
    def identity() -> "Rigid":
        return Rigid(sp.ImmutableMatrix(sp.eye(3)), sp.ImmutableMatrix(sp.zeros(3, 1)))

    @staticmethod
    def rot_x(angle) -> "Rigid":
        return Rigid(sp.ImmutableMatrix(rot_x(*cos_sin(angle))), sp.ImmutableMatrix(sp.zeros(3, 1)))

    @staticmethod
    def rot_z(angle) -> "Rigid":
        return Rigid(sp.ImmutableMatrix(rot_z(*cos_sin(angle))), sp.ImmutableMatrix(sp.zeros(3, 1)))

    @staticmethod
    def trans(x=0, y=0, z=0) -> "Rigid":
        return Rigid(sp.ImmutableMatrix(sp.eye(3)), sp.ImmutableMatrix([x, y, z]))

    def __mul__(self, other: "Rigid") -> "Rigid":
        return Rigid(sp.ImmutableMatrix(self.R * other.R), sp.ImmutableMatrix(self.R * other.p + self.p))

    @property
    def moves(self) -> bool:
        """Whether the translation is non-zero."""
        return any(x != 0 for x in self.p)

    def matrix(self) -> sp.Matrix:
        """The 4x4 homogeneous matrix."""
        T = sp.eye(4)
        T[:3, :3] = self.R
        T[:3, 3] = self.p
        return T


def rot_x(cos_a, sin_a) -> sp.Matrix:
    return sp.Matrix([[1, 0, 0], [0, cos_a, -sin_a], [0, sin_a, cos_a]])


def rot_z(cos_t, sin_t) -> sp.Matrix:
    return sp.Matrix([[cos_t, -sin_t, 0], [sin_t, cos_t, 0], [0, 0, 1]])


@dataclass(frozen=True)
class JointModel:
    type: str  # REVOLUTE | PRISMATIC
    placement: Rigid
    offset: sp.Expr  # the joint coordinate (angle or length) at q = 0
    frame: Rigid

    @property
    def revolute(self) -> bool:
        return self.type == REVOLUTE

    def motion(self, coordinate) -> Rigid:
        """Rz(coordinate) or Tz(coordinate); coordinate = offset + q."""
        return Rigid.rot_z(coordinate) if self.revolute else Rigid.trans(z=coordinate)

    def joint_frame_at_zero(self) -> sp.Matrix:
        """J_i at q = 0 in link frame i-1 (placement * motion(offset)), 4x4, exact."""
        return (self.placement * self.motion(self.offset)).matrix()

    def transform(self, q) -> sp.Matrix:
        """T(i-1, i)(q), 4x4, for a numeric or symbolic q."""
        return (self.placement * self.motion(self.offset + q) * self.frame).matrix()


# --- numpy face ----------------------------------------------------------------------------

def _floats(matrix) -> np.ndarray:
    # Exact products first, floats last: cos(pi/2) stays an exact zero.
    return np.array([[float(x) for x in matrix.row(r)] for r in range(matrix.rows)], dtype=float)


@functools.lru_cache(maxsize=256)  # a joint model's (immutable) matrices, asked for on every block of samples
def _constant(matrix) -> np.ndarray:
    out = _floats(matrix)
    out.flags.writeable = False
    return out


@dataclass(frozen=True)
class JointPose:
    """Joint i and link frame i in the base frame, per sample."""

    axis: np.ndarray  # (T, 3) z of J_i: the direction the joint turns about or slides along
    point: np.ndarray  # (T, 3) origin of J_i, a point on a revolute joint's axis
    R: np.ndarray  # (T, 3, 3) rotation of link frame i
    origin: np.ndarray  # (T, 3) origin of link frame i


def forward_kinematics(models, q) -> list[JointPose]:
    """Base-frame poses of every joint and link frame for joint positions q (T, N)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    samples = q.shape[0]
    R = np.broadcast_to(np.eye(3), (samples, 3, 3)).copy()
    o = np.zeros((samples, 3))
    poses = []
    # The stacks of 3x3 products as one matrix product each (R's rows stacked: (3T, 3) @ (3, 3)),
    # the turn about z as its two columns: a stack of small products is several times slower.
    for i, model in enumerate(models):
        place_R, place_p = _constant(model.placement.R), _constant(model.placement.p)[:, 0]
        frame_R, frame_p = _constant(model.frame.R), _constant(model.frame.p)[:, 0]
        coordinate = float(model.offset) + q[:, i]
        o = o + _times(R, place_p)
        R = _times(R, place_R)
        if model.revolute:
            R = _turned(R, coordinate)
        else:
            o = o + coordinate[:, None] * R[:, :, 2]
        axis, point = R[:, :, 2].copy(), o.copy()
        o = o + _times(R, frame_p)
        R = _times(R, frame_R)
        poses.append(JointPose(axis, point, R.copy(), o.copy()))
    return poses


def _times(R: np.ndarray, M: np.ndarray) -> np.ndarray:
    """R[t] @ M for every t: (T, 3, 3) times a constant (3, 3) matrix or (3,) vector."""
    return (R.reshape(-1, 3) @ M).reshape(R.shape[:2] + M.shape[1:])


def _turned(R: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """R[t] @ Rz(angle[t]): the first two columns turned, the third kept."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    x, y = R[:, :, 0], R[:, :, 1]
    return np.stack([x * c + y * s, y * c - x * s, R[:, :, 2]], axis=-1)
