"""Forward dynamics by the articulated-body algorithm (Featherstone), as straight-line code.

The rival of the L D L^T of M (forward_dynamics.py): both are derived for every arm and the
one with fewer operations is emitted (forward_dynamics.forward_dynamics). Spatial vectors in
link frame i at its origin O_i, motion [w; v], force [n; f]; the link's spatial inertia from
the standard parameters (m, h = m c, J about O_i) is [[J, [h x]], [[h x]^T, m E]], as the
Newton-Euler of newton_euler.py has it (N = J wd + h x a, F = m a + wd x h). Gravity enters
as the base's acceleration [0; -g].

  pass 1 (base to tip)  v_i = X_i v_(i-1) + S_i qd_i, c_i = v_i x (S_i qd_i), p_i = v_i x* I_i v_i
  pass 2 (tip to base)  U = I^A S, D = S^T U, u = tau - S^T p^A;
                        the parent gets X^T (I^A - U U^T / D) X and X^T (p^A + I^a c + U u / D)
  pass 3 (base to tip)  a' = X a_(i-1) + c_i, qdd_i = (u_i - U^T a') / D, a_i = a' + S qdd_i

X_i crosses joint i as the recursion of kinematics.py does: shift by `before` in frame i-1,
turn by R^T, shift by `after` in frame i. The inertia goes back the same way in blocks,
[[A, B], [B^T, C]] (A, C symmetric), so that only the distinct entries become variables.
"""

from __future__ import annotations

import sympy as sp

from ..parameters import PER_LINK
from .coriolis import model_inputs, start
from .models import Derivation, Model
from .program import Program, add, cross, mat_t_vec, mat_vec, scale

ZERO = [sp.Integer(0)] * 3


def _skew(d):
    return sp.Matrix([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])


def _sym_let(program: Program, M: sp.Matrix) -> sp.Matrix:
    """A symmetric matrix's upper triangle as variables, mirrored."""
    n = M.shape[0]
    out = sp.zeros(n, n)
    for r in range(n):
        for c in range(r, n):
            out[r, c] = out[c, r] = program.let(M[r, c])
    return out


def _mat_let(program: Program, M: sp.Matrix) -> sp.Matrix:
    return M.applyfunc(program.let)


class Blocks:
    """A symmetric spatial inertia [[A, B], [B^T, C]] in 3x3 blocks."""

    def __init__(self, A, B, C):
        self.A, self.B, self.C = A, B, C

    def times(self, w, v):
        """The force [A w + B v; B^T w + C v] of a motion [w; v]."""
        return add(mat_vec(self.A, w), mat_vec(self.B, v)), add(mat_t_vec(self.B, w), mat_vec(self.C, v))

    def shifted(self, program: Program, d) -> "Blocks":
        """The same inertia about the point Q = P - d (P its reference point): T_f I T_m with
        T_m = [[E, 0], [-[d x], E]] (v_P = v_Q + w x d), T_f = [[E, [d x]], [0, E]]."""
        if all(x == 0 for x in d):
            return self
        D = _skew(d)
        B = _mat_let(program, self.B + D * self.C)
        BD = self.B * D
        A = _sym_let(program, self.A - BD - BD.T - D * self.C * D)
        return Blocks(A, B, self.C)

    def rotated(self, program: Program, R) -> "Blocks":
        """The same inertia in the parent frame: each block R X R^T."""
        def sym(X):
            RX = _mat_let(program, R * X)
            return _sym_let(program, RX * R.T)
        return Blocks(sym(self.A), _mat_let(program, _mat_let(program, R * self.B) * R.T), sym(self.C))


def link_inertia(s10) -> Blocks:
    m, h, (xx, xy, xz, yy, yz, zz) = s10[0], s10[1:4], s10[4:10]
    J = sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    return Blocks(J, _skew(h), m * sp.eye(3))


def motion_cross(w, v, w2, v2):
    return cross(w, w2), add(cross(w, v2), cross(v, w2))


def force_cross(w, v, n, f):
    return add(cross(w, n), cross(v, f)), cross(w, f)


def dot(a, b):
    return sp.Add(*(x * y for x, y in zip(a, b)))


def articulated_body(derivation: Derivation, base=None) -> Model:
    """base: the full kind's BaseSet, to read the grouped parameters (Derivation._grouped)."""
    program, sym, chain = start(derivation)
    n, lets = derivation.n, program.let_vector
    params = derivation._grouped(program, base)
    tau = [sp.Symbol(f"tau{i + 1}", real=True) for i in range(n)]
    geo = chain.geometry
    R = [_mat_let(program, g.R) for g in geo]

    def to_child(i, w, v):
        """A motion of frame i-1 at O_(i-1) in frame i at O_i."""
        v = add(v, cross(w, geo[i].before))
        w, v = lets(mat_t_vec(R[i], w)), lets(mat_t_vec(R[i], v))
        return w, lets(add(v, cross(w, geo[i].after)))

    def to_parent(i, nm, f):
        """A force of frame i at O_i in frame i-1 at O_(i-1) (newton_euler.Chain.to_parent)."""
        nm = add(nm, cross(geo[i].after, f))
        f, nm = lets(mat_vec(R[i], f)), lets(mat_vec(R[i], nm))
        return lets(add(nm, cross(geo[i].before, f))), f

    S = [(g.spin, cross(g.spin, g.after)) if g.revolute else (ZERO, g.slide) for g in geo]
    # pass 1: velocities, bias accelerations and bias forces
    inertia, bias_acc, bias = [], [], []
    w, v = ZERO, ZERO
    for i in range(n):
        program.section = f"link {i + 1}: velocities (articulated body)"
        w, v = to_child(i, w, v)
        jw, jv = scale(sym.qd[i], S[i][0]), scale(sym.qd[i], S[i][1])
        w, v = lets(add(w, jw)), lets(add(v, jv))
        bias_acc.append(tuple(lets(x) for x in motion_cross(w, v, jw, jv)))
        I = link_inertia(params[PER_LINK * i: PER_LINK * (i + 1)])
        inertia.append(I)
        bias.append(tuple(lets(x) for x in force_cross(w, v, *(lets(x) for x in I.times(w, v)))))
    # pass 2: articulated inertias, tip to base
    U, D_inverse, u = [None] * n, [None] * n, [None] * n
    for i in reversed(range(n)):
        program.section = f"link {i + 1}: articulated inertia"
        I, (pn, pf), (sw, sv) = inertia[i], bias[i], S[i]
        Un, Uf = (lets(x) for x in I.times(sw, sv))
        U[i] = (Un, Uf)
        D_inverse[i] = program.let(1 / program.let(dot(sw, Un) + dot(sv, Uf)))
        u[i] = program.let(tau[i] - dot(sw, pn) - dot(sv, pf))
        if i == 0:
            break
        Ud = [program.let(x * D_inverse[i]) for x in Un + Uf]
        A = _sym_let(program, I.A - sp.Matrix(Un) * sp.Matrix(Ud[:3]).T)
        B = _mat_let(program, I.B - sp.Matrix(Un) * sp.Matrix(Ud[3:]).T)
        C = _sym_let(program, I.C - sp.Matrix(Uf) * sp.Matrix(Ud[3:]).T)
        Ia = Blocks(A, B, C)
        cn, cf = Ia.times(*bias_acc[i])
        pa_n = lets(add(pn, cn, scale(u[i], Ud[:3])))
        pa_f = lets(add(pf, cf, scale(u[i], Ud[3:])))
        # into the parent: shift to X, turn, shift to O_(i-1)
        moved = Ia.shifted(program, geo[i].after)
        moved = moved.rotated(program, R[i]).shifted(program, geo[i].before)
        parent = inertia[i - 1]
        inertia[i - 1] = Blocks(_sym_let(program, parent.A + moved.A), _mat_let(program, parent.B + moved.B),
                                _sym_let(program, parent.C + moved.C))
        fn, ff = to_parent(i, pa_n, pa_f)
        bias[i - 1] = (lets(add(bias[i - 1][0], fn)), lets(add(bias[i - 1][1], ff)))
    # pass 3: accelerations, base to tip
    qdd = []
    w, v = ZERO, program.let_vector([-g for g in derivation.robot.gravity])
    for i in range(n):
        program.section = f"link {i + 1}: acceleration (articulated body)"
        w, v = to_child(i, w, v)
        w, v = lets(add(w, bias_acc[i][0])), lets(add(v, bias_acc[i][1]))
        qdd.append(program.let((u[i] - dot(U[i][0], w) - dot(U[i][1], v)) * D_inverse[i]))
        w, v = lets(add(w, scale(qdd[i], S[i][0]))), lets(add(v, scale(qdd[i], S[i][1])))
    return Model("forward_dynamics", model_inputs(derivation, sym, qd=True, gravity=True, tau=tau), qdd, (n,),
                 "forward dynamics qdd = M^-1 (tau - c - g), articulated-body algorithm", program, sym.trig)
