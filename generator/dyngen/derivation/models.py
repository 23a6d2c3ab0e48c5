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
from .composite import mass_matrix_columns
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


GROUPING_LIMIT = 10  # largest |K| entry of a standard parameter that rnea, gravity and M group into the base coefficients


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
    # With a BaseSet, each function first forms its base coefficients pi = K s (a few products
    # with the link lengths) and runs the recursion on s* = (pi on the base columns, 0 on the
    # others): Y s = Y_b K s = Y s*, and every product with a zero parameter drops out
    # (Khalil and Kleinfinger's customised Newton-Euler in the grouped parameters).

    def rnea(self, base=None) -> Model:
        program, sym, chain = self._start()
        params = self._grouped(program, base)
        tau = self._interleaved(program, chain, sym.qd, sym.qdd, params)
        return Model("rnea", self._joint_inputs(sym, "q", "qd", "qdd") + [self._params_input()] + self._gravity_inputs(),
                     tau, (self.n,), "inverse dynamics tau = M(q) qdd + c(q, qd) + g(q) (Newton-Euler)",
                     program, sym.trig)

    def rnea_nominal(self, base, p_values) -> Model:
        """rnea with fixed dynamic parameters p_values folded in as exact numbers (what a
        controller with fixed parameters, or CasADi with baked parameters, runs): the YAML's
        decimals as written, s(p) and pi = K s computed here in rationals, so every product with
        a zero coefficient drops out and differences like ZZ - YY are one constant."""
        program, sym, chain = self._start()
        exact = [sp.Rational(repr(float(v))) for v in p_values]
        s = [x for i in range(self.n) for x in standard_from_dynamic_link(exact[PER_LINK * i: PER_LINK * (i + 1)])]
        kept = _ungroupable(base)  # their large factors would cancel in float (_grouped)
        params = self._placed(base, [sp.Add(*(k * v for j, (k, v) in enumerate(zip(row, s)) if k != 0 and j not in kept))
                                     for row in base.K])
        for j in kept:
            params[j] = s[j]
        tau = self._interleaved(program, chain, sym.qd, sym.qdd, params)
        return Model("rnea_nominal", self._joint_inputs(sym, "q", "qd", "qdd") + self._gravity_inputs(),
                     tau, (self.n,), "inverse dynamics at fixed parameters (Newton-Euler)", program, sym.trig)

    def inverse_dynamics(self, base) -> Model:
        """tau = Y_b(q, qd, qdd) pi_full from the base coefficients themselves (full kind)."""
        program, sym, chain = self._start()
        pi = [sp.Symbol(f"pi{k}", real=True) for k in range(base.rank)]
        tau = self._interleaved(program, chain, sym.qd, sym.qdd, self._placed(base, pi))
        return Model("inverse_dynamics", self._joint_inputs(sym, "q", "qd", "qdd")
                     + [Input("pi_full", pi, ARGUMENTS["pi_full"].meaning)] + self._gravity_inputs(),
                     tau, (self.n,), "inverse dynamics over the base coefficients (Newton-Euler)", program, sym.trig)

    def gravity(self, base=None) -> Model:
        program, sym, chain = self._start()
        params = self._grouped(program, base)
        zero = [0] * self.n
        g = self._interleaved(program, chain, zero, zero, params)
        return Model("gravity", self._joint_inputs(sym, "q") + [self._params_input()] + self._gravity_inputs(),
                     g, (self.n,), "gravity vector g(q)", program, sym.trig)

    def mass_matrix(self, base=None) -> Model:
        program, sym, chain = self._start()
        M = mass_matrix_columns(chain, self._grouped(program, base))  # composite bodies (derivation/composite.py)
        return Model("mass_matrix", self._joint_inputs(sym, "q") + [self._params_input()], list(M),
                     (self.n, self.n), "inertia matrix M(q), row-major", program, sym.trig)

    def _grouped(self, program, base) -> list:
        """The parameters the recursion reads: s itself, or s* from pi = K s (see above), grouped
        column by column. A standard parameter whose column of K has an entry above
        GROUPING_LIMIT in size (a regrouping that divides by a short length, 1/0.0203 on the
        PUMA 560) is not grouped: such a factor makes pi and the products with it cancel in float
        (2e-4 of the torques instead of 2e-6). It keeps its own place in the recursion and the
        coefficients leave it out. Exact either way: column j of Y is Y_b times column j of K, so
        Y s = Y_b (K' s) + sum over the kept j of Y_j s_j, with K' = K without the kept columns.
        The other example arms' largest entries (1/0.4 on the LWR, 6.5 on the UR5) cost nothing
        in float (bench/bench_opcounts.py), so all their parameters are grouped."""
        if base is None:
            return self.s
        program.section = f"base coefficients pi_{base.kind} = K s"
        kept = _ungroupable(base)
        params = self._placed(base, [_linear_form(program, [0 if j in kept else k for j, k in enumerate(row)], self.s)
                                     for row in base.K])
        for j in kept:
            params[j] = self.s[j]
        return params

    def _placed(self, base, pi) -> list:
        params = [sp.Integer(0)] * len(self.s)
        for value, column in zip(pi, base.pivots):
            params[column] = value
        return params

    def _interleaved(self, program, chain, qd, qdd, params):
        """Joint torques, each link's wrench right after its motion (Chain.forward says why)."""
        wrenches = []

        def wrench(i, motion):
            program.section = f"link {i + 1}: link wrench"
            wrenches.append(link_wrench(program, motion, params[PER_LINK * i: PER_LINK * (i + 1)]))

        chain.forward(qd, qdd, self.robot.gravity, then=wrench)
        return chain.backward(wrenches)

    def _tau(self, program, chain, motions, params):
        wrenches = []
        for i, motion in enumerate(motions):
            program.section = f"link {i + 1}: link wrench"
            wrenches.append(link_wrench(program, motion, params[PER_LINK * i: PER_LINK * (i + 1)]))
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


def _ungroupable(base) -> set:
    """Standard parameters (non-base columns) whose column of K has an entry above GROUPING_LIMIT."""
    return {j for row in base.K for j, k in enumerate(row) if abs(k) > GROUPING_LIMIT}


def _linear_form(program: Program, row, s) -> sp.Expr:
    """sum_j row_j s_j with one product per distinct |row_j| != 1: the standard parameters that
    share a factor are summed first (the masses of the links beyond a length, say), and those
    sums and their products are variables that the other rows reuse."""
    groups: dict = {}
    for k, x in zip(row, s):
        if k != 0:
            groups.setdefault(abs(k), []).append(x if k > 0 else -x)
    terms = []
    for k in sorted(groups):
        total = sp.Add(*groups[k])
        terms.append(total if k == 1 else program.let(k * program.let(total)))
    return program.let(sp.Add(*terms))


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
