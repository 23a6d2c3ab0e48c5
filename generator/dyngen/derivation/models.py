"""Every quantity dyngen emits, as straight-line programs over named inputs.

A `Model` is the math of one emitted C function: its inputs (name, symbols, meaning),
its pruned assignments and its flat outputs. Regressors come full (all 10N standard
parameters); reduction picks their base columns. The inertia regressor Y_m is not one of
them: it is emitted from its factors, `unit_accelerations` (derivation/inertia.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from ..catalogue import ARGUMENTS
from ..description import Robot
from ..parameters import PER_LINK, dynamic_symbols, standard_from_dynamic_link, standard_symbols
from .newton_euler import Chain, joint_symbols, link_wrench
from .program import Program


@dataclass
class Input:
    name: str  # the C argument
    symbols: list  # entry k of the argument is symbols[k]
    doc: str


@dataclass
class Model:
    name: str
    inputs: list[Input]
    outputs: list  # flat, row-major
    shape: tuple
    doc: str
    program: Program = field(repr=False)
    trig: dict = field(default_factory=dict)  # trig symbol -> (joint, "sin" | "cos")

    @property
    def assignments(self):
        return self.program.pruned(self.outputs)


class Derivation:
    """Builds the models of one robot; each model has its own program."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.n = robot.dof
        self.s = standard_symbols(self.n)
        self.p = dynamic_symbols(self.n)

    # ---- inputs -------------------------------------------------------------------------

    def _joint_inputs(self, sym, *which):
        return [Input(w, getattr(sym, w), ARGUMENTS[w].meaning) for w in which]

    def _gravity_inputs(self):
        g = list(self.robot.gravity_symbols)
        return [Input("gravity", g, ARGUMENTS["gravity"].meaning + " " + ", ".join(map(str, g)))] if g else []

    def _params_input(self):
        return Input("s", self.s, ARGUMENTS["s"].meaning)

    def _start(self):
        program = Program()
        sym = joint_symbols(self.robot)
        return program, sym, Chain(self.robot, program, sym)

    # ---- inverse dynamics and its conveniences ------------------------------------------

    def rnea(self) -> Model:
        program, sym, chain = self._start()
        motions = chain.forward(sym.qd, sym.qdd, self.robot.gravity)
        tau = self._tau(program, chain, motions)
        return Model("rnea", self._joint_inputs(sym, "q", "qd", "qdd") + [self._params_input()] + self._gravity_inputs(),
                     tau, (self.n,), "inverse dynamics tau = M(q) qdd + c(q, qd) + g(q) (Newton-Euler)",
                     program, sym.trig)

    def gravity(self) -> Model:
        program, sym, chain = self._start()
        zero = [0] * self.n
        g = self._tau(program, chain, chain.forward(zero, zero, self.robot.gravity))
        return Model("gravity", self._joint_inputs(sym, "q") + [self._params_input()] + self._gravity_inputs(),
                     g, (self.n,), "gravity vector g(q)", program, sym.trig)

    def mass_matrix(self) -> Model:
        program, sym, chain = self._start()
        M = sp.zeros(self.n, self.n)
        for k in range(self.n):
            unit = [int(j == k) for j in range(self.n)]
            column = self._tau(program, chain, chain.forward([0] * self.n, unit, [0, 0, 0]))
            for j in range(k + 1):
                M[j, k] = M[k, j] = column[j]
        return Model("mass_matrix", self._joint_inputs(sym, "q") + [self._params_input()], list(M),
                     (self.n, self.n), "inertia matrix M(q), row-major", program, sym.trig)

    def _tau(self, program, chain, motions):
        wrenches = []
        for i, motion in enumerate(motions):
            program.section = f"link {i + 1}: link wrench"
            wrenches.append(link_wrench(program, motion, self.s[PER_LINK * i: PER_LINK * (i + 1)]))
        return chain.backward(wrenches)

    # ---- regressors (all 10N columns) ---------------------------------------------------

    def regressor(self, kind: str) -> Model:
        """kind: 'gravity' (N x 10N), 'full' (N x 10N) or 'full_without_gravity' (N x 10N, the full
        regressor with gravity zero: its base set is the inertia matrix's, see reduction/base.py)."""
        program, sym, chain = self._start()
        zero = [0] * self.n
        if kind == "full":
            rows = chain.regressor_columns(chain.forward(sym.qd, sym.qdd, self.robot.gravity))
            inputs = self._joint_inputs(sym, "q", "qd", "qdd") + self._gravity_inputs()
        elif kind == "full_without_gravity":
            rows = chain.regressor_columns(chain.forward(sym.qd, sym.qdd, [0, 0, 0]))
            inputs = self._joint_inputs(sym, "q", "qd", "qdd")
        elif kind == "gravity":
            rows = chain.regressor_columns(chain.forward(zero, zero, self.robot.gravity))
            inputs = self._joint_inputs(sym, "q") + self._gravity_inputs()
        else:
            raise ValueError(kind)
        shape = (len(rows), PER_LINK * self.n)
        return Model(f"regressor_{kind}", inputs, [x for row in rows for x in row], shape,
                     f"{kind} regressor over all standard parameters", program, sym.trig)

    def unit_accelerations(self) -> Model:
        """The motions S_j^i = (wd, a) of link i under a unit acceleration of joint j <= i (zero
        velocity, no gravity), link-major (derivation/inertia.py): the inertia regressor's
        factors. Shape n(n+1)/2 x 6."""
        program, sym, chain = self._start()
        outputs = [x for per_link in chain.unit_accelerations() for motion in per_link
                   for x in (*motion.wd, *motion.a)]
        return Model("unit_accelerations", self._joint_inputs(sym, "q"), outputs, (len(outputs) // 6, 6),
                     "angular and linear acceleration of each link under a unit acceleration of each joint",
                     program, sym.trig)

    # ---- parameters ---------------------------------------------------------------------

    def standard_from_dynamic(self) -> Model:
        program = Program()
        out = []
        for i in range(self.n):
            program.section = f"link {i + 1}"
            out += program.let_vector(standard_from_dynamic_link(self.p[PER_LINK * i: PER_LINK * (i + 1)]))
        return Model("standard_from_dynamic", [Input("p", self.p, ARGUMENTS["p"].meaning)], out,
                     (PER_LINK * self.n,), "standard parameters s from dynamic parameters p", program)


def coefficient_model(derivation: Derivation, base, kind: str) -> Model:
    """pi(p): the base coefficients of one regressor from the dynamic parameters."""
    program = Program()
    s_exprs = []
    for i in range(derivation.n):
        program.section = f"link {i + 1}: standard parameters"
        s_exprs += program.let_vector(standard_from_dynamic_link(derivation.p[PER_LINK * i: PER_LINK * (i + 1)]))
    program.section = "coefficients"
    outputs = [program.let(sp.Add(*(k * s for k, s in zip(row, s_exprs) if k != 0))) for row in base.K]
    return Model(f"pi_{kind}", [Input("p", derivation.p, ARGUMENTS["p"].meaning)], outputs,
                 (len(outputs),), f"{kind} base coefficients", program)


def base_regressor_outputs(model: Model, base) -> list:
    """The pivot columns of a full regressor model, row-major."""
    rows, cols = model.shape
    return [model.outputs[r * cols + c] for r in range(rows) for c in base.pivots]


def coefficient_jacobian_model(derivation: Derivation, base, kind: str) -> Model:
    """d pi / d p (rank x 10N, row-major): pi = K s(p), and s depends on its own link's p only."""
    program = Program()
    n_params = PER_LINK * derivation.n
    J = [[sp.Integer(0)] * n_params for _ in base.K]
    for i in range(derivation.n):
        program.section = f"link {i + 1}"
        p_link = derivation.p[PER_LINK * i: PER_LINK * (i + 1)]
        s_link = standard_from_dynamic_link(p_link)
        ds = [[program.let(sp.diff(s_link[j], p_link[l])) for l in range(PER_LINK)] for j in range(PER_LINK)]
        for r, row in enumerate(base.K):
            for l in range(PER_LINK):
                J[r][PER_LINK * i + l] = program.let(
                    sp.Add(*(row[PER_LINK * i + j] * ds[j][l] for j in range(PER_LINK) if row[PER_LINK * i + j] != 0)))
    outputs = [x for row in J for x in row]
    return Model(f"pi_{kind}_jacobian", [Input("p", derivation.p, ARGUMENTS["p"].meaning)], outputs,
                 (len(base.K), n_params), f"Jacobian of pi_{kind} with respect to p", program)
