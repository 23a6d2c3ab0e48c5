"""Newton-Euler with two velocity arguments: the Christoffel Coriolis matrix and the Slotine-Li regressor.

The velocity terms of inverse dynamics form a quadratic form c(v) = sum_jk Gamma_ijk v_j v_k
whose Christoffel symbols Gamma_ijk are symmetric in j, k. Its polarisation, the symmetric
bilinear form B(u, v) = sum_jk Gamma_ijk u_j v_k, is unique, so C(q, qd) y = B(qd, y) is
the Christoffel Coriolis matrix (M_dot - 2C skew-symmetric, M_dot = C + C^T).

The recursion computes B by carrying two angular velocities, w(u) and w(v), and writing
every product of two velocity-linear quantities symmetrically: w_a w_b becomes
w_a(u) w_b(v) + w_a(v) w_b(u), which is 2 B; with u = qd/2 it is B(qd, v) at the price of N
halvings. Accelerations, U, the link wrenches and the backward pass are linear in those
products, so the Motion of newton_euler.py carries them and its consumers (link_wrench,
Chain.backward, Chain.regressor_columns) are used unchanged.
"""

from __future__ import annotations

import sympy as sp

from ..catalogue import ARGUMENTS
from ..parameters import PER_LINK
from .models import Derivation, Input, Model
from .newton_euler import Chain, Motion, _u_matrix, joint_symbols, link_wrench  # _u_matrix: linear in ww, as here
from .program import Program, add, cross, mat_t_vec, mat_vec, scale

ZERO = [sp.Integer(0)] * 3
HALF = sp.Rational(1, 2)  # u = qd / 2: 2 B(qd / 2, v) = B(qd, v)


def bilinear_forward(chain: Chain, u, v, qdd, gravity) -> list[Motion]:
    """Every link's Motion for L(qdd, gravity) + 2 B(u, v): Motion.ww holds w_a(u) w_b(v) + w_a(v) w_b(u),
    Motion.w holds w(v)."""
    program = chain.program
    rest = Motion(ZERO, ZERO, program.let_vector([-g for g in gravity]), sp.zeros(3, 3), {})
    motions, wu_parent = [], ZERO
    for i in range(len(chain.geometry)):
        program.section = f"link {i + 1}: velocities and accelerations"
        parent = motions[-1] if motions else rest
        motion, wu_parent = _step(chain, i, parent, wu_parent, u[i], v[i], qdd[i])
        motions.append(motion)
    return motions


def _step(chain: Chain, i, parent: Motion, wu_parent, u_i, v_i, qdd_i):
    let, lets = chain.program.let, chain.program.let_vector
    geo = chain.geometry[i]
    a = add(parent.a, mat_vec(parent.U, geo.before))
    wu_in, wv_in = lets(mat_t_vec(geo.R, wu_parent)), lets(mat_t_vec(geo.R, parent.w))
    wd_in, a_in = lets(mat_t_vec(geo.R, parent.wd)), lets(mat_t_vec(geo.R, a))
    wu, wv = lets(add(wu_in, scale(u_i, geo.spin))), lets(add(wv_in, scale(v_i, geo.spin)))
    wd = lets(add(wd_in, scale(qdd_i, geo.spin), cross(wu_in, scale(v_i, geo.spin)), cross(wv_in, scale(u_i, geo.spin))))
    ww = {(r, c): let(wu[r] * wv[c] + wv[r] * wu[c]) for r in range(3) for c in range(r, 3)}
    U = _u_matrix(let, ww, wd)
    a_in = add(a_in, mat_vec(U, geo.after), scale(qdd_i, geo.slide),
               scale(2, add(cross(wu, scale(v_i, geo.slide)), cross(wv, scale(u_i, geo.slide)))))
    return Motion(wv, wd, lets(a_in), U, ww), wu


def start(derivation: Derivation):
    program = Program()
    sym = joint_symbols(derivation.robot)
    return program, sym, Chain(derivation.robot, program, sym)


def joint_forces(derivation: Derivation, chain: Chain, motions, params=None) -> list:
    """Joint forces of the link motions with the standard parameters s as symbols (or params,
    expressions of them: the grouped parameters of Derivation._grouped)."""
    params = derivation.s if params is None else params
    wrenches = []
    for i, motion in enumerate(motions):
        chain.program.section = f"link {i + 1}: link wrench"
        wrenches.append(link_wrench(chain.program, motion, params[PER_LINK * i: PER_LINK * (i + 1)]))
    return chain.backward(wrenches)


def coriolis_columns(derivation: Derivation, chain: Chain, qd, params=None) -> sp.Matrix:
    """C(q, qd) in the chain's program, column j = B(qd, e_j)."""
    n = derivation.n
    half = chain.program.let_vector([HALF * x for x in qd])
    C = sp.zeros(n, n)
    for j in range(n):
        unit = [int(k == j) for k in range(n)]
        column = joint_forces(derivation, chain, bilinear_forward(chain, half, unit, [0] * n, [0, 0, 0]), params)
        for i in range(n):
            C[i, j] = column[i]
    return C


def coriolis_matrix(derivation: Derivation, base=None) -> Model:
    """base: the inertia kind's BaseSet (C is M's Christoffel symbols; they keep M, Derivation.mass_matrix)."""
    program, sym, chain = start(derivation)
    C = coriolis_columns(derivation, chain, sym.qd, derivation._grouped(program, base))
    return Model("coriolis_matrix", model_inputs(derivation, sym, qd=True), list(C),
                 (derivation.n, derivation.n), "Christoffel Coriolis matrix C(q, qd), row-major", program, sym.trig)


def reference_symbols(n: int) -> dict:
    return {"qr_d": [sp.Symbol(f"qrd{i + 1}", real=True) for i in range(n)],
            "qr_dd": [sp.Symbol(f"qrdd{i + 1}", real=True) for i in range(n)]}


def slotine_li_regressor(derivation: Derivation) -> Model:
    """Y(q, qd, qr_d, qr_dd) over all 10N standard parameters: Y s = M qr_dd + C(q, qd) qr_d + g."""
    program, sym, chain = start(derivation)
    ref = reference_symbols(derivation.n)
    half = program.let_vector([HALF * x for x in sym.qd])
    rows = chain.regressor_columns(bilinear_forward(chain, half, ref["qr_d"], ref["qr_dd"], derivation.robot.gravity))
    inputs = model_inputs(derivation, sym, qd=True, s=False, gravity=True, **ref)
    return Model("regressor_slotine_li", inputs, [x for row in rows for x in row], (len(rows), PER_LINK * derivation.n),
                 "Slotine-Li regressor over all standard parameters", program, sym.trig)


def model_inputs(derivation: Derivation, sym, q=True, qd=False, qdd=False, s=True, gravity=False, **extra) -> list[Input]:
    """A model's inputs in the catalogue's order: q, qd, qdd, then the extra vectors (name ->
    symbols, e.g. qr_d, tau), s, gravity (only when gravity has symbols)."""
    inputs = [Input(w, getattr(sym, w), ARGUMENTS[w].meaning) for w, on in (("q", q), ("qd", qd), ("qdd", qdd)) if on]
    inputs += [Input(name, symbols, ARGUMENTS[name].meaning) for name, symbols in extra.items()]
    if s:
        inputs.append(Input("s", derivation.s, ARGUMENTS["s"].meaning))
    g = list(derivation.robot.gravity_symbols)
    if gravity and g:
        inputs.append(Input("gravity", g, ARGUMENTS["gravity"].meaning + " " + ", ".join(map(str, g))))
    return inputs
