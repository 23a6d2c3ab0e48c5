"""Analytic derivatives of inverse and forward dynamics, by forward mode over the program's lets.

Every assignment x = f(y_1, ..., y_m) of a program is a small polynomial in earlier variables,
so its tangent along one input direction is dx = sum_k (df/dy_k) dy_k over the y_k whose
tangent is not zero, itself a new let: the derivative program has the same shape (and the
same common subexpressions) as the program it differentiates, with no expanded expression
ever formed. The direction q_k seeds ds_k = c_k, dc_k = -s_k (revolute) or dq_k = 1
(prismatic); qd_k seeds dqd_k = 1.

Inverse dynamics:  D = [d tau / d q | d tau / d qd]  (N x 2N) of rnea at (q, qd, qdd).
Forward dynamics:  d qdd / d(q, qd) = -M^-1 D at qdd = FD(q, qd, tau), with D taken with qdd
held fixed (its lets frozen) and M^-1 applied through the L D L^T factors FD already has.
"""

from __future__ import annotations

import sympy as sp

from .coriolis import joint_forces, model_inputs, start
from .forward_dynamics import forward_dynamics_in, solve
from .models import Derivation, Model
from .newton_euler import joint_symbols
from .program import Program


class ForwardMode:
    """Tangents of some outputs of a program along input directions, as new lets of the same
    program; the partial derivatives of an assignment are shared by every direction."""

    def __init__(self, program: Program, outputs, frozen=frozenset()):
        """frozen: symbols held constant (tangent zero); what only they need is not visited."""
        self.program, self.outputs, self.frozen = program, list(outputs), frozen
        needed = set().union(*(sp.sympify(o).free_symbols for o in self.outputs))
        kept = []
        for a in reversed(program.assignments):  # before any tangent is added
            if a.symbol in needed and a.symbol not in frozen:
                kept.append(a)
                needed |= a.expr.free_symbols
        self.assignments = kept[::-1]
        self._partials = {}

    def tangents(self, seed: dict) -> list:
        """seed: input symbol -> its tangent; whatever the seed does not reach has tangent zero."""
        t = dict(seed)
        for a in self.assignments:
            moved = sorted((f for f in a.expr.free_symbols if t.get(f, 0) != 0), key=lambda f: f.name)
            if moved:
                t[a.symbol] = self.program.let(sp.Add(*(self._partial(a, f) * t[f] for f in moved)))
        return [self.program.let(sp.Add(*(sp.diff(o, f) * t[f] for f in sp.sympify(o).free_symbols
                                          if t.get(f, 0) != 0))) for o in self.outputs]

    def _partial(self, a, f):
        key = (a.symbol, f)
        if key not in self._partials:
            self._partials[key] = self.program.let(sp.diff(a.expr, f))
        return self._partials[key]


def directions(derivation: Derivation, sym) -> list[dict]:
    """Seeds of the 2N directions q_1..q_N, qd_1..qd_N."""
    trig = {(joint, fn): s for s, (joint, fn) in sym.trig.items()}
    seeds = []
    for k, joint in enumerate(derivation.robot.joint_models):
        if joint.revolute:
            s, c = trig[(k, "sin")], trig[(k, "cos")]
            seeds.append({s: c, c: -s})
        else:
            seeds.append({sym.q[k]: sp.Integer(1)})
    return seeds + [{sym.qd[k]: sp.Integer(1)} for k in range(derivation.n)]


def rnea_derivatives(derivation: Derivation, base=None) -> Model:
    program, sym, chain = start(derivation)
    params = derivation._grouped(program, base)
    tau = joint_forces(derivation, chain, chain.forward(sym.qd, sym.qdd, derivation.robot.gravity), params)
    forward_mode, columns = ForwardMode(program, tau), []
    for k, seed in enumerate(directions(derivation, sym)):
        program.section = f"d tau / d {'q' if k < derivation.n else 'qd'}{k % derivation.n + 1}"
        columns.append(forward_mode.tangents(seed))
    n = derivation.n
    return Model("rnea_derivatives", model_inputs(derivation, sym, qd=True, qdd=True, gravity=True),
                 [columns[k][i] for i in range(n) for k in range(2 * n)], (n, 2 * n),
                 "[d tau / d q | d tau / d qd], row-major", program, sym.trig)


def forward_dynamics_derivatives(derivation: Derivation, base=None) -> Model:
    fd = forward_dynamics_in(derivation, base)
    program, sym, n = fd.program, fd.symbols, derivation.n
    tau = joint_forces(derivation, fd.chain, fd.chain.forward(sym.qd, fd.qdd, derivation.robot.gravity), fd.params)
    frozen = frozenset(x if x.is_Symbol else -x for x in map(sp.sympify, fd.qdd))  # each a let (or its negative)
    assert all(x.is_Symbol for x in frozen), fd.qdd
    forward_mode, columns = ForwardMode(program, tau, frozen), []
    for k, seed in enumerate(directions(derivation, sym)):
        program.section = f"d qdd / d {'q' if k < n else 'qd'}{k % n + 1} = -M^-1 d tau / d ..."
        partial = forward_mode.tangents(seed)
        columns.append(solve(program, fd.factors, [-x for x in partial]))
    return Model("forward_dynamics_derivatives", model_inputs(derivation, sym, qd=True, gravity=True, tau=fd.tau),
                 [columns[k][i] for i in range(n) for k in range(2 * n)], (n, 2 * n),
                 "[d qdd / d q | d qdd / d qd], row-major", program, sym.trig)


def mass_matrix_derivative(derivation: Derivation, base=None) -> Model:
    """M_dot = sum_k dM/dq_k qd_k: one forward-mode direction (along qd) over M's composite-body
    program (ForwardMode above), about half the operations of C + C^T (which equals it).
    base: the inertia kind's BaseSet (M over its grouped parameters, as mass_matrix has it)."""
    M = derivation.mass_matrix(base)
    sym = joint_symbols(derivation.robot)
    trig = {(joint, fn): s for s, (joint, fn) in M.trig.items()}
    seed = {}
    for k, joint in enumerate(derivation.robot.joint_models):
        if joint.revolute:
            s, c = trig[(k, "sin")], trig[(k, "cos")]
            seed.update({s: c * sym.qd[k], c: -s * sym.qd[k]})
        else:
            seed[sym.q[k]] = sym.qd[k]
    n = derivation.n
    upper = [(i, j) for i in range(n) for j in range(i, n)]
    M.program.section = "M_dot = dM/dq qd"
    tangents = dict(zip(upper, ForwardMode(M.program, [M.outputs[i * n + j] for i, j in upper]).tangents(seed)))
    Md = [tangents[(min(i, j), max(i, j))] for i in range(n) for j in range(n)]
    return Model("mass_matrix_derivative", model_inputs(derivation, sym, qd=True), Md,
                 (n, n), "time derivative of the inertia matrix, row-major", M.program, M.trig)
