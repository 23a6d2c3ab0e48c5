"""One call per control cycle: g(q), M(q) and c(q, qd) (optionally the flange's J and Jdot qd)
from one program, so that the joint angles' sines and cosines are computed once and every
subexpression the three share (rotations, link motions) is emitted once.

The models are the same derivations as the separate functions (derivation/models.py): a
Derivation whose programs are all one shared program, so gravity() and mass_matrix() build into
it; c is the Newton-Euler pass with qdd = 0 and no gravity. Outputs are concatenated:
g (N), M (N x N, row-major), c (N) [, J (6 x N), Jdot qd (6)].
"""

from __future__ import annotations

from .kinematics_functions import base_frames, flange_bias_acceleration, jacobian_columns
from .models import Derivation, Model
from .newton_euler import Chain, joint_symbols
from .program import Program


class _SharedProgram(Derivation):
    """A Derivation whose every model builds into the same program and chain."""

    def __init__(self, robot):
        super().__init__(robot)
        program, sym = Program(), joint_symbols(robot)
        self.shared = (program, sym, Chain(robot, program, sym))

    def _start(self):
        return self.shared

    def coriolis_vector(self, base=None) -> list:
        program, sym, chain = self.shared
        motions = chain.forward(sym.qd, [0] * self.n, [0, 0, 0])
        return self._tau(program, chain, motions, self._grouped(program, base))


def control_model(robot, bases=None, with_jacobian: bool = False) -> Model:
    """bases: kind -> BaseSet, to run each part over its grouped parameters as the separate
    functions do (Derivation.rnea); None: over the standard parameters."""
    bases = bases or {}
    derivation = _SharedProgram(robot)
    g, M = derivation.gravity(bases.get("gravity")), derivation.mass_matrix(bases.get("inertia"))
    c = derivation.coriolis_vector(bases.get("full"))
    program, sym, _ = derivation.shared
    outputs = list(g.outputs) + list(M.outputs) + c
    inputs = M.inputs[:1] + derivation._joint_inputs(sym, "qd") + g.inputs[1:]  # q, qd, s[, gravity]
    name, doc = "control", "gravity vector, inertia matrix and velocity terms"
    if with_jacobian:
        frames = base_frames(robot, program, sym)
        program.section = "flange: Jacobian"
        outputs += jacobian_columns(program, frames, frames.flange_o, robot.dof)
        outputs += flange_bias_acceleration(program, frames, sym.qd)
        name, doc = "control_with_jacobian", doc + ", flange Jacobian and Jdot qd"
    return Model(name, inputs, outputs, (len(outputs),), doc, program, sym.trig)
