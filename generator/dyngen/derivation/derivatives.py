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


class ReverseMode:
    """Gradients of single outputs of a program with respect to its inputs, as new lets: one
    sweep per output, last assignment first, each assignment x = f(y_1..y_m) adding
    (df/dy_k) adj(x) to adj(y_k); the partials are shared by every sweep.

    angles: sine or cosine symbol -> (angle symbol, its derivative along the angle): an
    assignment's partial along a joint angle, (df/ds) c - (df/dc) s, is one shared let (often
    the rotation's other component), so a sweep pays one product for it instead of two."""

    def __init__(self, program: Program, outputs, frozen=frozenset(), angles=None):
        self.forward = ForwardMode(program, outputs, frozen)
        self.program, self.frozen, self.angles = program, frozen, angles or {}
        self._partials = {}

    def _inputs(self, a):
        """(input symbol, partial of a.expr along it), angles merged."""
        moved = {}
        for f in sorted(a.expr.free_symbols - self.frozen, key=lambda f: f.name):
            if f in self.angles:
                angle, derivative = self.angles[f]
                moved.setdefault(angle, []).append(sp.diff(a.expr, f) * derivative)
            else:
                moved[f] = None
        for f, parts in moved.items():
            if (a.symbol, f) not in self._partials:
                self._partials[(a.symbol, f)] = (self.forward._partial(a, f) if parts is None
                                                 else self.program.let(sp.expand(sp.Add(*parts))))
            yield f, self._partials[(a.symbol, f)]

    def gradient(self, output, inputs) -> list:
        """d output / d y for every y of inputs (symbols, or angles); zero where output does not depend on y."""
        output = sp.sympify(output)
        assert not output.free_symbols & set(self.angles), output  # an output is a let (or an input)
        terms = {f: [sp.diff(output, f)] for f in output.free_symbols - self.frozen}
        for a in reversed(self.forward.assignments):
            if a.symbol not in terms:
                continue
            adjoint = self.program.let(sp.Add(*terms.pop(a.symbol)))
            if adjoint == 0:
                continue
            for f, partial in self._inputs(a):
                terms.setdefault(f, []).append(partial * adjoint)
        return [self.program.let(sp.Add(*terms.get(y, []))) for y in inputs]


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


def gradient_rows(program: Program, derivation: Derivation, sym, tau, frozen=frozenset()) -> list:
    """[d tau_i / d q | d tau_i / d qd] for every i, by reverse mode (one sweep per joint)."""
    trig = {(joint, fn): s for s, (joint, fn) in sym.trig.items()}
    angles = {}
    for k, joint in enumerate(derivation.robot.joint_models):
        if joint.revolute:
            s, c = trig[(k, "sin")], trig[(k, "cos")]
            angles.update({s: (sym.q[k], c), c: (sym.q[k], -s)})
    reverse, rows = ReverseMode(program, tau, frozen, angles), []
    for i, t in enumerate(tau):
        program.section = f"row {i + 1}: d tau{i + 1} / d (q, qd)"
        rows.append(reverse.gradient(t, list(sym.q) + list(sym.qd)))
    return rows


def rnea_derivatives(derivation: Derivation, base=None) -> Model:
    program, sym, chain = start(derivation)
    params = derivation._grouped(program, base)
    tau = joint_forces(derivation, chain, chain.forward(sym.qd, sym.qdd, derivation.robot.gravity), params)
    rows = gradient_rows(program, derivation, sym, tau)
    n = derivation.n
    return Model("rnea_derivatives", model_inputs(derivation, sym, qd=True, qdd=True, gravity=True),
                 [x for row in rows for x in row], (n, 2 * n),
                 "[d tau / d q | d tau / d qd], row-major", program, sym.trig)


def forward_dynamics_derivatives(derivation: Derivation, base=None) -> Model:
    fd = forward_dynamics_in(derivation, base)
    program, sym, n = fd.program, fd.symbols, derivation.n
    tau = joint_forces(derivation, fd.chain, fd.chain.forward(sym.qd, fd.qdd, derivation.robot.gravity), fd.params)
    frozen = frozenset(x if x.is_Symbol else -x for x in map(sp.sympify, fd.qdd))  # each a let (or its negative)
    assert all(x.is_Symbol for x in frozen), fd.qdd
    rows, columns = gradient_rows(program, derivation, sym, tau, frozen), []
    for k in range(2 * n):
        program.section = f"d qdd / d {'q' if k < n else 'qd'}{k % n + 1} = -M^-1 d tau / d ..."
        columns.append(solve(program, fd.factors, [-row[k] for row in rows]))
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
