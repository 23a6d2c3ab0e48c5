"""The inertia matrix by composite bodies (Walker and Orin's method 3, the CRBA).

Column k of M is the torque that a unit acceleration of joint k needs when nothing moves:
only links k..N accelerate, all together as one rigid body, so their wrench is the composite
body's (m, h, J of links k..N summed in frame k about O_k) times link k's unit motion, and
joints j <= k feel it through the backward recursion (Chain.to_parent, Chain.joint_torque).
The composite bodies are built once, tip to base, so the work is one inertia transform per
link plus one wrench carried down per entry of M's upper triangle, where the per-column
Newton-Euler passes (Derivation.mass_matrix's former form) recomputed every link's motion
and wrench for every column.
"""

from __future__ import annotations

import sympy as sp

from .newton_euler import ZERO, Chain, Motion, link_wrench
from .program import add, mat_vec

PER_LINK = 10


def _inertia_matrix(J):
    xx, xy, xz, yy, yz, zz = J
    return sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def composite_bodies(chain: Chain, params) -> list:
    """[(m, h, J) of links i..N, frame i, about O_i] for every link i; params: 10 per link."""
    program, n = chain.program, len(chain.geometry)
    bodies = [None] * n
    for i in reversed(range(n)):
        program.section = f"link {i + 1}: composite body"
        own = params[PER_LINK * i: PER_LINK * (i + 1)]
        m, h, J = own[0], list(own[1:4]), _inertia_matrix(own[4:10])
        if i + 1 < n:
            cm, ch, cJ = bodies[i + 1]
            geo = chain.geometry[i + 1]
            R = geo.R
            p = add(geo.before, mat_vec(R, geo.after))  # O_(i+1) in frame i
            hR = program.let_vector(mat_vec(R, ch))
            RJ = R * cJ * R.T
            pp = sum(x * x for x in p)
            ph = sum(x * y for x, y in zip(p, hR))
            shift = sp.Matrix(3, 3, lambda r, c: cm * ((pp if r == c else 0) - p[r] * p[c])
                              + (2 * ph if r == c else 0) - p[r] * hR[c] - hR[r] * p[c])
            m = program.let(m + cm)
            h = program.let_vector(add(h, hR, [cm * x for x in p]))
            J = J + RJ + shift
            if geo.revolute:
                J = _in_double_angles(program, J, chain.angle(i + 1))
        J = sp.Matrix(3, 3, lambda r, c: program.let(J[min(r, c), max(r, c)]))
        bodies[i] = (m, h, J)
    return bodies


def _in_double_angles(program, J, angle) -> sp.Matrix:
    """J (symmetric, quadratic in the joint's cosine c and sine s, as R cJ R^T and the shift by
    p(c, s) make it) with c^2 = 1/2 + d, s^2 = 1/2 - d and c s = e, where d = c^2 - 1/2 and
    e = c s are formed once per joint (cos 2q / 2 and sin 2q / 2). Why: c^2 a - 2 c s b + s^2 e'
    is 6 products, (a + e')/2 + d (a - e') - 2 e b is 3, and the factoring (emission/factoring.py)
    then shares d and e across the entries. Exact, as c^2 + s^2 = 1; in float d and e are
    within an ulp of their values, as c^2 and c s were."""
    c, s = angle
    d, e = program.let(c * c - sp.Rational(1, 2)), program.let(c * s)
    def rewritten(x):
        rest, along_d, along_e = [], [], []
        for term in sp.Add.make_args(sp.expand(x)):
            powers = term.as_powers_dict()
            i, j = int(powers.get(c, 0)), int(powers.get(s, 0))
            other = term / (c ** i * s ** j)
            if (i, j) == (1, 1):
                along_e.append(other)
            elif (i, j) in ((2, 0), (0, 2)):
                sign = 1 if i == 2 else -1
                rest.append(other / 2)
                along_d.append(sign * other)
            else:
                rest.append(term)
        # the turn B d + C e is one variable: J[1, 1] reads the same with both signs flipped
        turn = program.let(program.let(sp.Add(*along_d)) * d + program.let(sp.Add(*along_e)) * e)
        return sp.Add(*rest) + turn

    return sp.Matrix(3, 3, lambda r, k: rewritten(J[r, k]) if r <= k else 0)


def mass_matrix_columns(chain: Chain, params) -> sp.Matrix:
    """M (symmetric) from the composite bodies."""
    program, n = chain.program, len(chain.geometry)
    bodies = composite_bodies(chain, params)
    rest = Motion(ZERO, ZERO, ZERO, sp.zeros(3, 3), {})
    M = sp.zeros(n, n)
    for k in range(n):
        program.section = f"column {k + 1}: composite wrench"
        m, h, J = bodies[k]
        motion = chain.step(k, rest, 0, 1)  # link k under a unit acceleration of joint k
        f, nm = link_wrench(program, motion, [m, *h, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2]])
        M[k, k] = chain.joint_torque(k, f, nm)
        for j in reversed(range(k)):
            program.section = f"column {k + 1}: to joint {j + 1}"
            f, nm = chain.to_parent(j + 1, f, nm)
            M[j, k] = M[k, j] = chain.joint_torque(j, f, nm)
    return M

