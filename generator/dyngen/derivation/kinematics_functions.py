"""Forward kinematics, geometric Jacobians and Jdot qd in the base frame, as straight-line programs.

Built from the same joint models as the dynamics (description/joint_model.py): link frame i is
T(0, i) = T(0, i-1) placement_i motion_i(q) frame_i, accumulated in the base frame with one
variable per matrix entry. Joint i's axis z_i (the z of its joint frame J_i) and a point p_i on
it (J_i's origin) give the Jacobian columns of a point e:

    revolute   [z_i x (e - p_i); z_i]        prismatic  [z_i; 0]

rows [v; w]: the linear velocity of the point, then the angular velocity of its link, both in
base axes (Pinocchio's LOCAL_WORLD_ALIGNED). `Jdot qd` is the classical acceleration of the
flange at qdd = 0 (d/dt (J qd) = J qdd + Jdot qd), from a forward recursion in the base frame:
a point r fixed in a body moves with a_o + wd x r + w x (w x r), a revolute joint adds
w x (qd z) to the angular acceleration, a prismatic one the Coriolis term 2 w x (qd z).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..catalogue import ARGUMENTS
from ..description.joint_model import Rigid, rot_z
from .models import Input, Model
from .newton_euler import Chain, joint_symbols
from .program import Program, add, cross, mat_vec

ZERO = [sp.Integer(0)] * 3


@dataclass
class Frames:
    """Base-frame geometry of one arm inside a Program (entries are program variables)."""

    R: list  # per link: rotation of link frame i (sp.Matrix 3x3)
    o: list  # per link: origin of link frame i
    axis: list  # per joint: z_i
    point: list  # per joint: origin of J_i, on a revolute joint's axis
    revolute: list  # per joint
    flange_R: sp.Matrix
    flange_o: list


def _lets_matrix(program: Program, M) -> sp.Matrix:
    return sp.Matrix(3, 3, [program.let(x) for x in M])


def base_frames(robot, program: Program, sym) -> Frames:
    """The pose of every link frame, joint axis and the flange (last link frame times the
    description's tool offset), in the base frame."""
    Chain(robot, program, sym)  # names the joint angles' sines and cosines (s_i, c_i) as the dynamics does
    trig = {v: k for k, v in sym.trig.items()}
    R, o = sp.eye(3), list(ZERO)
    frames = Frames([], [], [], [], [], None, None)
    for i, model in enumerate(robot.joint_models):
        program.section = f"link {i + 1}: pose"
        place, frame = model.placement, model.frame
        point = program.let_vector(add(o, mat_vec(R, list(place.p))))
        R_joint = _lets_matrix(program, R * place.R)
        axis = [R_joint[r, 2] for r in range(3)]
        if model.revolute:
            R_joint = _lets_matrix(program, R_joint * rot_z(trig[(i, "cos")], trig[(i, "sin")]))
            o_joint = point
        else:
            coordinate = program.let(model.offset + sym.q[i])
            o_joint = program.let_vector(add(point, [coordinate * z for z in axis]))
        R = _lets_matrix(program, R_joint * frame.R)
        o = program.let_vector(add(o_joint, mat_vec(R_joint, list(frame.p))))
        frames.R.append(R), frames.o.append(o), frames.axis.append(axis)
        frames.point.append(point), frames.revolute.append(model.revolute)
    tool = robot.tool or Rigid.identity()
    program.section = "flange"
    frames.flange_R = _lets_matrix(program, R * tool.R)
    frames.flange_o = program.let_vector(add(o, mat_vec(R, list(tool.p))))
    return frames


def pose_entries(R, o) -> list:
    """4x4 homogeneous matrix, row-major."""
    return [x for r in range(3) for x in (R[r, 0], R[r, 1], R[r, 2], o[r])] + [0, 0, 0, 1]


def jacobian_columns(program: Program, frames: Frames, point, joints: int) -> list:
    """The 6 x N Jacobian (row-major) of `point`, moved by the first `joints` joints."""
    n = len(frames.axis)
    J = [[sp.Integer(0)] * n for _ in range(6)]
    for j in range(joints):
        z = frames.axis[j]
        if frames.revolute[j]:
            linear = program.let_vector(cross(z, add(point, [-x for x in frames.point[j]])))
            column = linear + z
        else:
            column = z + ZERO
        for r in range(6):
            J[r][j] = column[r]
    return [x for row in J for x in row]


def flange_bias_acceleration(program: Program, frames: Frames, qd) -> list:
    """Jdot qd of the flange: [classical linear acceleration of its origin; angular
    acceleration of the last link] at qdd = 0, base frame."""
    let = program.let_vector
    w, wd, a, o = list(ZERO), list(ZERO), list(ZERO), list(ZERO)

    def carry(a, wd, w, r):  # a point r from the origin, fixed in the body (w, wd)
        return let(add(a, cross(wd, r), cross(w, let(cross(w, r)))))

    for i, z in enumerate(frames.axis):
        program.section = f"link {i + 1}: bias acceleration"
        a_point = carry(a, wd, w, let(add(frames.point[i], [-x for x in o])))
        r = let(add(frames.o[i], [-x for x in frames.point[i]]))
        spin = [qd[i] * x for x in z]
        if frames.revolute[i]:
            wd = let(add(wd, cross(w, spin)))
            w = let(add(w, spin))
            a = carry(a_point, wd, w, r)
        else:
            a = let(add(carry(a_point, wd, w, r), [2 * x for x in cross(w, spin)]))
        o = frames.o[i]
    program.section = "flange: bias acceleration"
    a = carry(a, wd, w, let(add(frames.flange_o, [-x for x in o])))
    return a + wd


class KinematicsModels:
    """The models of the kinematics functions of one robot (each with its own program)."""

    def __init__(self, robot):
        self.robot = robot
        self.n = robot.dof

    def _start(self):
        program, sym = Program(), joint_symbols(self.robot)
        return program, sym, base_frames(self.robot, program, sym), Input

    def _model(self, name, inputs, outputs, shape, doc, program, sym):
        return Model(name, inputs, outputs, shape, doc, program, sym.trig)

    def link_poses(self):
        program, sym, frames, Input = self._start()
        outputs = [x for R, o in zip(frames.R, frames.o) for x in pose_entries(R, o)]
        return self._model("link_poses", [Input("q", sym.q, ARGUMENTS["q"].meaning)], outputs, (4 * self.n, 4),
                           "4x4 pose of every link frame in the base frame", program, sym)

    def flange_pose(self):
        program, sym, frames, Input = self._start()
        return self._model("flange_pose", [Input("q", sym.q, ARGUMENTS["q"].meaning)],
                           pose_entries(frames.flange_R, frames.flange_o), (4, 4),
                           "4x4 pose of the flange (tool) frame in the base frame", program, sym)

    def jacobian(self):
        program, sym, frames, Input = self._start()
        program.section = "flange: Jacobian"
        outputs = jacobian_columns(program, frames, frames.flange_o, self.n)
        return self._model("jacobian", [Input("q", sym.q, ARGUMENTS["q"].meaning)], outputs, (6, self.n),
                           "geometric Jacobian of the flange in the base frame", program, sym)

    def link_jacobians(self):
        program, sym, frames, Input = self._start()
        outputs = []
        for i in range(self.n):
            program.section = f"link {i + 1}: Jacobian"
            outputs += jacobian_columns(program, frames, frames.o[i], i + 1)
        return self._model("link_jacobians", [Input("q", sym.q, ARGUMENTS["q"].meaning)], outputs, (6 * self.n, self.n),
                           "geometric Jacobian of every link frame's origin in the base frame", program, sym)

    def jacobian_dot_qd(self):
        program, sym, frames, Input = self._start()
        outputs = flange_bias_acceleration(program, frames, sym.qd)
        inputs = [Input(w, getattr(sym, w), ARGUMENTS[w].meaning) for w in ("q", "qd")]
        return self._model("jacobian_dot_qd", inputs, outputs, (6,), "Jdot qd of the flange", program, sym)

    def all(self) -> dict:
        return {name: getattr(self, name)() for name in
                ("link_poses", "flange_pose", "jacobian", "link_jacobians", "jacobian_dot_qd")}
