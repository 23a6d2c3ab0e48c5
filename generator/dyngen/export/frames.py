"""What URDF and MJCF share: joint placements from the joint models, inertials in joint frames,
checks that a simulator can load the parameters, and number formatting.

Simulators turn a joint about (or slide along) the z axis of its own frame, and a child
link's frame is that joint frame: exactly the joint model's J_i (description/joint_model.py),
T(i-1, i)(q) = placement_i * motion_i(q) * frame_i. With pre_i = placement_i * motion_i(0)
(the joint's offset included) and post_i = frame_i, the simulator's joint frame J_i sits at
post_{i-1} * pre_i in J_{i-1} (post_0 = I, J_0 = frame 0), link frame i is J_i * post_i, and
the simulator's q is the description's q (offsets are in pre).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..parameters import consistency_problem, inertia_array

# Relative tolerance of the physical-consistency check: round-off in parameters written on the
# boundary (a thin rod's A + B = C) is forgiven; MuJoCo loads such a body.
CONSISTENCY_TOL = 1e-12


def _to_float(T: sp.Matrix) -> np.ndarray:
    # Products are formed exactly first, so cos(pi/2) etc. give exact zeros in the files.
    return np.array([[float(x) for x in T.row(r)] for r in range(T.rows)], dtype=float)


@dataclass(frozen=True)
class Placement:
    """Joint i: where its frame J_i sits in J_{i-1}, and where link (DH) frame i sits in J_i."""

    origin: np.ndarray  # 4x4, J_i in J_{i-1} at q = 0
    post: np.ndarray  # 4x4, link (DH) frame i in J_i


def placements(robot) -> list[Placement]:
    out = []
    prev_post = sp.eye(4)
    for model in robot.joint_models:
        pre, post = model.joint_frame_at_zero(), model.frame.matrix()
        out.append(Placement(_to_float(prev_post * pre), _to_float(post)))
        prev_post = post
    return out


@dataclass(frozen=True)
class Inertial:
    """A link's inertial data in its joint frame J_i: CoM position and inertia about the CoM
    with J_i's axes (rotated there so files need no inertial orientation)."""

    mass: float
    com: np.ndarray  # (3,)
    inertia: np.ndarray  # 3x3, matrix entries (products are the off-diagonal entries)


def link_matrix(pi) -> np.ndarray:
    """One link's inertia about its CoM, from its dynamic parameters."""
    return inertia_array(pi[4:10])


def check_consistent(p: np.ndarray) -> None:
    """Raise ValueError naming the first link whose parameters no rigid body has: simulators
    refuse them (MuJoCo) or silently misbehave. parameters.consistency_problem, to CONSISTENCY_TOL."""
    for i, pi in enumerate(p, start=1):
        problem = consistency_problem(pi, -CONSISTENCY_TOL)
        if problem is not None:
            raise ValueError(f"link {i}: {problem}; simulators cannot load it")


def link_parameters(robot, p) -> np.ndarray:
    """p (10N,) checked for shape, finiteness and physical consistency -> (N, 10)."""
    p = np.asarray(p, dtype=float)
    n = robot.dof
    if p.shape != (10 * n,):
        raise ValueError(f"{robot.name}: expected {10 * n} dynamic parameters (10 per link), got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError(f"{robot.name}: dynamic parameters must be finite")
    P = p.reshape(n, 10)
    check_consistent(P)
    return P


def inertials(P: np.ndarray, places: list[Placement]) -> list[Inertial]:
    out = []
    for pi, place in zip(P, places):
        R, t = place.post[:3, :3], place.post[:3, 3]
        I = R @ link_matrix(pi) @ R.T
        out.append(Inertial(float(pi[0]), t + R @ pi[1:4], 0.5 * (I + I.T)))
    return out


def numeric_gravity(robot) -> np.ndarray:
    """The gravity vector as floats; ValueError if it has symbols (a file needs numbers)."""
    free = robot.gravity_symbols
    if free:
        names = ", ".join(s.name for s in free)
        raise ValueError(f"{robot.source}: gravity {list(map(str, robot.gravity))} contains symbols ({names}); "
                         f"a simulator file needs numbers: give gravity as numbers in the YAML to export")
    return np.array([float(g) for g in robot.gravity])


# --- numbers and rotations ---------------------------------------------------------------

def fmt(x) -> str:
    """Shortest text that reads back as the same double (repr); -0.0 written as 0.0."""
    v = float(x) + 0.0
    if not math.isfinite(v):
        raise ValueError(f"non-finite number {v!r} in export")
    return repr(v)


def vec(xs) -> str:
    return " ".join(fmt(x) for x in xs)


def rpy(R: np.ndarray) -> tuple[float, float, float]:
    """URDF roll-pitch-yaw (fixed axes X, Y, Z): R = Rz(yaw) Ry(pitch) Rx(roll)."""
    R = np.asarray(R, dtype=float)
    cp = math.hypot(R[0, 0], R[1, 0])
    pitch = math.atan2(-R[2, 0], cp)
    if cp > 1e-9:
        return math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0])
    # Gimbal lock (pitch = +-pi/2): only roll -+ yaw is defined; put it all into yaw.
    # With roll = 0: R[0,1] = -sin(yaw), R[1,1] = cos(yaw) for either sign of pitch.
    return 0.0, pitch, math.atan2(-R[0, 1], R[1, 1])


def quaternion(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd: largest pivot first)."""
    R = np.asarray(R, dtype=float)
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    k = int(np.argmax([tr, R[0, 0], R[1, 1], R[2, 2]]))
    if k == 0:
        s = 2.0 * math.sqrt(1.0 + tr)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    elif k == 1:
        s = 2.0 * math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [(R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s]
    elif k == 2:
        s = 2.0 * math.sqrt(1.0 - R[0, 0] + R[1, 1] - R[2, 2])
        q = [(R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 - R[0, 0] - R[1, 1] + R[2, 2])
        q = [(R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    if q[0] < 0:  # one of the two signs, for stable output
        q = -q
    return q / np.linalg.norm(q)
