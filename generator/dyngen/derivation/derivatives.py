"""Analytic derivatives of inverse and forward dynamics, by reverse mode over the program's lets.

Every assignment x = f(y_1, ..., y_m) of a program is a small polynomial in earlier variables.
Reverse mode (ReverseMode) sweeps the assignments one output depends on, last first, adding
(df/dy_k) adj(x) to adj(y_k): one sweep per joint torque tau_i gives the whole row
[d tau_i / d q | d tau_i / d qd], N sweeps where forward mode (ForwardMode: one sweep per input
direction, dx = sum_k (df/dy_k) dy_k) needs 2N. Both add lets to the same program (its common
subexpressions carry over, no expanded expression is ever formed), and the partials df/dy_k are
lets shared by every sweep. A joint angle's sine and cosine are merged into the angle: an
assignment's partial along q_k is (df/ds_k) c_k - (df/dc_k) s_k, one let.

Inverse dynamics:  D = [d tau / d q | d tau / d qd]  (N x 2N) of rnea at (q, qd, qdd).
Forward dynamics:  d qdd / d(q, qd) = -M^-1 D at qdd = FD(q, qd, tau), with D taken with qdd
held fixed (its lets frozen) and M^-1 applied through the L D L^T factors FD already has.
Both read the grouped parameters (Derivation._grouped) when given the full kind's BaseSet.
M_dot (mass_matrix_derivative) is one forward-mode direction along qd.
"""

from __future__ import annotations

import sympy as sp

from .coriolis import joint_forces, model_inputs, start
from .forward_dynamics import forward_dynamics_in, solve
from .models import Derivation, Model
from .newton_euler import joint_symbols
from .program import Program


def reached(program: Program, outputs, frozen=frozenset()) -> list:
    """The assignments the outputs need, in order, those of the frozen symbols (held constant)
    and what only they need left out; taken before any derivative is added to the program."""
    needed = set().union(*(sp.sympify(o).free_symbols for o in outputs))
    kept = []
    for a in reversed(program.assignments):
        if a.symbol in needed and a.symbol not in frozen:
            kept.append(a)
            needed |= a.expr.free_symbols
    return kept[::-1]


class ForwardMode:
    """Tangents of some outputs of a program along input directions, as new lets of the same
    program; the partial derivatives of an assignment are shared by every direction."""

    def __init__(self, program: Program, outputs, frozen=frozenset()):
        """frozen: symbols held constant (tangent zero)."""
        self.program, self.outputs = program, list(outputs)
        self.assignments = reached(program, self.outputs, frozen)
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
        self.program, self.frozen, self.angles = program, frozen, angles or {}
        self.assignments = reached(program, outputs, frozen)
        self._partials = {}

    def _inputs(self, a):
        """(input symbol or angle, the partial of a.expr along it, a let)."""
        moved = {}
        for f in sorted(a.expr.free_symbols - self.frozen, key=lambda f: f.name):
            angle, derivative = self.angles.get(f, (f, 1))
            moved.setdefault(angle, []).append(sp.diff(a.expr, f) * derivative)
        for f, parts in moved.items():
            if (a.symbol, f) not in self._partials:
                merged = len(parts) > 1 or f not in a.expr.free_symbols  # along an angle
                self._partials[(a.symbol, f)] = self.program.let(sp.expand(sp.Add(*parts)) if merged else parts[0])
            yield f, self._partials[(a.symbol, f)]

    def gradient(self, output, inputs) -> list:
        """d output / d y for every y of inputs (symbols, or angles); zero where output does not depend on y."""
        output = sp.sympify(output)
        assert not output.free_symbols & set(self.angles), output  # an output is a let (or an input)
        terms = {f: [sp.diff(output, f)] for f in output.free_symbols - self.frozen}
        for a in reversed(self.assignments):
            if a.symbol not in terms:
                continue
            adjoint = self.program.let(sp.Add(*terms.pop(a.symbol)))
            if adjoint == 0:
                continue
            for f, partial in self._inputs(a):
                terms.setdefault(f, []).append(partial * adjoint)
        return [self.program.let(sp.Add(*terms.get(y, []))) for y in inputs]


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
