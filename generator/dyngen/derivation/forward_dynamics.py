"""Forward dynamics qdd = M(q)^-1 (tau - b(q, qd)) as straight-line code, two ways: the
articulated-body algorithm (articulated_body.py) and, here, M by composite bodies
(composite.py), the bias b = rnea(q, qd, 0) (gravity included) and a square-root-free
Cholesky factorisation M = L D L^T (a serial chain's M is dense: no sparsity to use beyond
its symmetry), all in one program so that the sines, cosines and rotations are shared.
The emitted forward_dynamics is the one with fewer operations for the arm; the derivatives of
forward dynamics (derivatives.py) always use the L D L^T factors, which apply M^-1 to 2N columns.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from .articulated_body import articulated_body
from .composite import mass_matrix_columns
from .coriolis import joint_forces, model_inputs, start
from .models import Derivation, Model
from .program import Program


@dataclass
class LDLT:
    """M = L D L^T: L unit lower triangular (L[(i, j)], i > j), the inverses of D's entries."""

    L: dict
    D_inverse: list


def factor(program: Program, M: sp.Matrix) -> LDLT:
    """~n^3/6 multiplications and n divisions; W[i][j] = L_ij D_j saves one product per term."""
    n = M.shape[0]
    program.section = "M = L D L^T"
    L, W, Dinv = {}, {}, []
    for i in range(n):
        for j in range(i):
            W[(i, j)] = program.let(M[i, j] - sp.Add(*(W[(i, k)] * L[(j, k)] for k in range(j))))
            L[(i, j)] = program.let(W[(i, j)] * Dinv[j])
        D = program.let(M[i, i] - sp.Add(*(W[(i, k)] * L[(i, k)] for k in range(i))))
        Dinv.append(program.let(1 / D))
    return LDLT(L, Dinv)


def solve(program: Program, f: LDLT, b) -> list:
    """x with L D L^T x = b."""
    n = len(b)
    y = []
    for i in range(n):
        y.append(program.let(b[i] - sp.Add(*(f.L[(i, k)] * y[k] for k in range(i)))))
    x = [None] * n
    for i in reversed(range(n)):
        x[i] = program.let(y[i] * f.D_inverse[i] - sp.Add(*(f.L[(k, i)] * x[k] for k in range(i + 1, n))))
    return x


@dataclass
class ForwardDynamics:
    """The pieces the derivatives of forward dynamics reuse."""

    program: Program
    symbols: object
    chain: object
    tau: list
    factors: LDLT
    qdd: list
    params: list  # the parameters the recursion read (s, or grouped)


def forward_dynamics_in(derivation: Derivation, base=None) -> ForwardDynamics:
    """base: the full kind's BaseSet, to run the recursion over the grouped parameters
    (Derivation._grouped: Y s = Y s* for every q, qd, qdd, so M and b are unchanged)."""
    program, sym, chain = start(derivation)
    n = derivation.n
    tau = [sp.Symbol(f"tau{i + 1}", real=True) for i in range(n)]
    params = derivation._grouped(program, base)
    # The bias before M: the scheduler (emission/schedule.py) breaks its ties in this order, and
    # with M first its 21-28 entries waited in registers or on the stack through the whole bias
    # pass; with the bias first only the n values tau - b wait through M, whose entries the
    # factorisation then reads as they come. Same operations; PUMA 560 FD 2480 -> 2395
    # instructions per call at -O2, 1991 -> 1894 with -march=native (probe loop, gcc 12), fewer
    # on every example arm (docs/fewer-operations.md item 13).
    bias = joint_forces(derivation, chain, chain.forward(sym.qd, [0] * n, derivation.robot.gravity), params)
    program.section = "qdd = M^-1 (tau - b)"
    rhs = [program.let(t - b) for t, b in zip(tau, bias)]
    M = mass_matrix_columns(chain, params)  # composite bodies: 245 products on the LWR, 642 from unit accelerations
    factors = factor(program, M)
    program.section = "qdd = M^-1 (tau - b)"
    qdd = solve(program, factors, rhs)
    return ForwardDynamics(program, sym, chain, tau, factors, qdd, params)


def ldlt_forward_dynamics(derivation: Derivation, base=None) -> Model:
    fd = forward_dynamics_in(derivation, base)
    return Model("forward_dynamics", model_inputs(derivation, fd.symbols, qd=True, gravity=True, tau=fd.tau), fd.qdd, (derivation.n,),
                 "forward dynamics qdd = M^-1 (tau - c - g), L D L^T", fd.program, fd.symbols.trig)


def candidates(derivation: Derivation, base=None) -> dict:
    """Both derivations of forward dynamics, by method name (base: the full kind's BaseSet)."""
    return {"ldlt": ldlt_forward_dynamics(derivation, base), "articulated_body": articulated_body(derivation, base)}


def forward_dynamics(derivation: Derivation, operations, base=None) -> Model:
    """The candidate with fewer operations (operations: model -> its count, the emitter's), the
    L D L^T on a tie: a fixed function of the arm."""
    models = candidates(derivation, base)
    return min(models.values(), key=lambda m: (operations(m), m is not models["ldlt"]))
