"""Symbolic recursive Newton-Euler in link frames, linear in the standard parameters.

Per link i (frame i, quantities at the frame origin O_i):
  forward:  w_i, wd_i, a_i and U_i = [wd_i x] + [w_i x]^2, so a point at r moves with U_i r;
  link:     F_i = m a_i + U_i h,   N_i = J wd_i + w_i x (J w_i) + h x a_i   (h = m c, J about O_i)
  backward: the subtree's wrench moved to the parent, the joint's share projected on its axis.
Gravity enters as the base acceleration a_0 = -g (Luh, Walker, Paul 1980).

The same forward pass feeds three consumers: the inverse dynamics with parameter symbols,
the body regressor (F_i, N_i as a 6x10 matrix linear in s_i, Pinocchio's building block)
and, through unit accelerations, the inertia matrix.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..description import Robot
from .kinematics import JointGeometry, joint_geometry
from .program import Program, add, cross, mat_t_vec, mat_vec, scale

ZERO = [sp.Integer(0)] * 3


@dataclass
class Motion:
    """Velocity state of link i in frame i: what its wrench needs."""

    w: list
    wd: list
    a: list  # acceleration of O_i (gravity included)
    U: sp.Matrix
    ww: dict  # products w_a * w_b, (a, b) with a <= b


@dataclass
class Symbols:
    """The symbols the generated functions read."""

    q: list
    qd: list
    qdd: list
    trig: dict  # symbol -> (joint index, "sin" | "cos")


def joint_symbols(robot: Robot) -> Symbols:
    n = robot.dof
    return Symbols(
        q=[sp.Symbol(f"q{i + 1}", real=True) for i in range(n)],
        qd=[sp.Symbol(f"qd{i + 1}", real=True) for i in range(n)],
        qdd=[sp.Symbol(f"qdd{i + 1}", real=True) for i in range(n)],
        trig={},
    )


class Chain:
    """The arm's joint models inside one Program: trig variables and per-joint geometry."""

    def __init__(self, robot: Robot, program: Program, symbols: Symbols):
        self.robot, self.program, self.symbols = robot, program, symbols
        self.geometry: list[JointGeometry] = []
        program.section = "joint angles"
        for i, model in enumerate(robot.joint_models):
            if model.revolute:
                s, c = sp.Symbol(f"s{i + 1}", real=True), sp.Symbol(f"c{i + 1}", real=True)
                symbols.trig[s], symbols.trig[c] = (i, "sin"), (i, "cos")
                self.geometry.append(joint_geometry(model, c, s, None))
            else:
                self.geometry.append(joint_geometry(model, None, None, program.let(model.offset + symbols.q[i])))

    def angle(self, i) -> tuple:
        """(cos, sin) symbols of revolute joint i's full angle."""
        by_fn = {fn: sym for sym, (joint, fn) in self.symbols.trig.items() if joint == i}
        return by_fn["cos"], by_fn["sin"]

    # ---- forward ---------------------------------------------------------------------

    def forward(self, qd, qdd, gravity, then=None) -> list[Motion]:
        """The links' motions, base to tip; then(i, motion), if given, right after each link's
        motion: the emitted code uses a link's motion before the next link's (fewer values live
        at once, so fewer spills to the stack)."""
        base = Motion(ZERO, ZERO, self.program.let_vector([-g for g in gravity]), sp.zeros(3, 3), {})
        motions = []
        for i in range(len(self.geometry)):
            self.program.section = f"link {i + 1}: velocities and accelerations"
            motions.append(self.step(i, motions[-1] if motions else base, qd[i], qdd[i]))
            if then is not None:
                then(i, motions[-1])
        return motions

    def unit_accelerations(self) -> list[list[Motion]]:
        """motions[i][j] (j <= i): link i's motion when joint j accelerates at 1, nothing moves
        and there is no gravity, i.e. forward(0, unit_j, 0)[i]. Its (wd, a) is column j of link
        i's Jacobian at O_i in frame i. Built link by link (all joints at once) so that the
        emitted code reads per link; links before joint j do not move, so O(n^2) motions."""
        rest = Motion(ZERO, ZERO, ZERO, sp.zeros(3, 3), {})
        motions: list[list[Motion]] = []
        for i in range(len(self.geometry)):
            self.program.section = f"link {i + 1}: unit accelerations"
            motions.append([self.step(i, motions[i - 1][j] if j < i else rest, 0, int(i == j)) for j in range(i + 1)])
        return motions

    def step(self, i, parent: Motion, qd_i, qdd_i) -> Motion:
        """Link i's motion from its parent's (link i-1's, or the base's) and joint i's rate and acceleration."""
        let, lets = self.program.let, self.program.let_vector
        geo = self.geometry[i]
        a = lets(add(parent.a, mat_vec(parent.U, geo.before)))  # at X, fixed in link i-1
        w_in, wd_in, a_in = lets(mat_t_vec(geo.R, parent.w)), lets(mat_t_vec(geo.R, parent.wd)), lets(mat_t_vec(geo.R, a))
        spin = scale(qd_i, geo.spin)
        w = lets(add(w_in, spin))
        wd = lets(add(wd_in, scale(qdd_i, geo.spin), cross(w_in, spin)))
        ww = {(r, c): let(w[r] * w[c]) for r in range(3) for c in range(r, 3)}
        U = _u_matrix(let, ww, wd)
        slide = scale(qd_i, geo.slide)
        a_in = add(a_in, mat_vec(U, geo.after), scale(qdd_i, geo.slide), scale(2, cross(w, slide)))
        return Motion(w, wd, lets(a_in), U, ww)

    # ---- backward --------------------------------------------------------------------

    def to_parent(self, i, f, n):
        """Wrench (f, n about O_i, frame i) of link i's subtree as seen in frame i-1 about O_(i-1)."""
        lets, geo = self.program.let_vector, self.geometry[i]
        n = lets(add(n, cross(geo.after, f)))  # about X
        f, n = lets(mat_vec(geo.R, f)), lets(mat_vec(geo.R, n))
        return f, lets(add(n, cross(geo.before, f)))

    def joint_torque(self, i, f, n):
        """Joint i's generalised force from link i's subtree wrench (f, n about O_i, frame i)."""
        geo = self.geometry[i]
        if not geo.revolute:  # a slide needs no moment
            return self.program.let(sp.Add(*(x * y for x, y in zip(geo.slide, f))))
        n = self.program.let_vector(add(n, cross(geo.after, f)))  # about X, which is on the axis
        return self.program.let(sp.Add(*(x * y for x, y in zip(geo.spin, n))))

    def backward(self, wrenches) -> list:
        """Joint torques from per-link wrenches [(F_i, N_i)], tip to base."""
        tau = [None] * len(wrenches)
        f, n = ZERO, ZERO
        for i in reversed(range(len(wrenches))):
            self.program.section = f"link {i + 1}: forces"
            F, N = wrenches[i]
            f, n = self.program.let_vector(add(F, f)), self.program.let_vector(add(N, n))
            tau[i] = self.joint_torque(i, f, n)
            if i > 0:
                f, n = self.to_parent(i, f, n)
        return tau

    def regressor_columns(self, motions):
        """tau's regressor: Y[j][10 i + k] for every joint j and standard parameter k of link i."""
        n_links = len(motions)
        Y = [[sp.Integer(0)] * (10 * n_links) for _ in range(n_links)]
        for i, motion in enumerate(motions):
            for k, (F, N) in enumerate(body_regressor(motion)):
                self.program.section = f"link {i + 1}: regressor"
                f, n = self.program.let_vector(F), self.program.let_vector(N)
                for j in reversed(range(i + 1)):
                    Y[j][10 * i + k] = self.joint_torque(j, f, n)
                    if j > 0:
                        f, n = self.to_parent(j, f, n)
        return Y


def _u_matrix(let, ww, wd) -> sp.Matrix:
    """[wd x] + [w x][w x], with [w x]^2 = w w^T - |w|^2 E from the products ww."""
    def sq(k):
        return ww[(k, k)]

    def prod(r, c):
        return ww[(min(r, c), max(r, c))]

    U = sp.zeros(3, 3)
    for r in range(3):
        others = [k for k in range(3) if k != r]
        U[r, r] = let(-(sq(others[0]) + sq(others[1])))
    skew = [[0, -wd[2], wd[1]], [wd[2], 0, -wd[0]], [-wd[1], wd[0], 0]]
    for r in range(3):
        for c in range(3):
            if r != c:
                U[r, c] = let(prod(r, c) + skew[r][c])
    return U


def link_wrench(program: Program, motion: Motion, s10) -> tuple[list, list]:
    """(F, N) of one link about its frame origin, with symbolic standard parameters s10."""
    m, h, J = s10[0], s10[1:4], s10[4:10]
    let = program.let_vector
    F = let(add(scale(m, motion.a), mat_vec(motion.U, h)))
    N = let(add(inertia_times(J, motion.wd), gyroscopic(J, motion.ww), cross(h, motion.a)))
    return F, N


def inertia_times(J, v):
    xx, xy, xz, yy, yz, zz = J
    return [xx * v[0] + xy * v[1] + xz * v[2], xy * v[0] + yy * v[1] + yz * v[2], xz * v[0] + yz * v[1] + zz * v[2]]


def gyroscopic(J, ww):
    """w x (J w) written with the products w_a w_b already formed for U: 12 instead of 15 products."""
    xx, xy, xz, yy, yz, zz = J
    w11, w12, w13, w22, w23, w33 = (ww[k] for k in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)))
    return [
        (zz - yy) * w23 + yz * (w22 - w33) + xz * w12 - xy * w13,
        (xx - zz) * w13 + xz * (w33 - w11) + xy * w23 - yz * w12,
        (yy - xx) * w12 + xy * (w11 - w22) + yz * w13 - xz * w23,
    ]


def body_regressor(motion: Motion):
    """(F, N) per standard parameter of one link: the 10 columns of its 6x10 body regressor."""
    a, U, wd, ww = motion.a, motion.U, motion.wd, motion.ww
    columns = [(a, ZERO)]  # m
    for k in range(3):  # h_x, h_y, h_z: F = U h, N = h x a
        e = [sp.Integer(int(k == r)) for r in range(3)]
        columns.append(([U[r, k] for r in range(3)], cross(e, a)))
    for k in range(6):  # XX, XY, XZ, YY, YZ, ZZ
        J = [sp.Integer(int(k == r)) for r in range(6)]
        columns.append((ZERO, add(inertia_times(J, wd), gyroscopic(J, ww))))
    return columns
