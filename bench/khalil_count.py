#!/usr/bin/env python3
"""The operation count of Khalil's customised Newton-Euler itself, on an example arm, with every
base coefficient general: the figure dyngen's `inverse_dynamics` is compared with (issue 24).

The recursion is SYMORO's `fixed_inverse_dynmodel` (Khalil's lab's tool: pysymoro/nealgos.py,
kinematics.compute_vel_acc) written out here in SymPy, in Khalil's modified DH, every element
of every intermediate vector and matrix a symbol of its own (SYMORO's `mat_replace`), with
Khalil's grouped parameters of a revolute chain (Khalil and Dombre, ch. 14): YY_j, MZ_j and M_j
of every link grouped into the link before, so link j has XXR, XY, XZ, YZ, ZZR, MX, MY and link 1
only ZZR1 (1 + 7 (n - 1) coefficients: 43 on the LWR, 36 on the RX-90, dyngen's base counts).
Zeros and ones drop out as SymPy builds each element, and the equations no joint torque reads
are dropped (Khalil's customisation). Counted with dyngen's own counter (emission/opcount.py).

    python bench/khalil_count.py [--arms lwr rx90] [--check]

--check runs the same recursion over the standard parameters (no grouping) on a `dh: modified`
arm and compares its torques with dyngen's symbolic rnea at random values (the recursion is
Khalil's; the grouping is his theorem, the count is over it).
"""
from __future__ import annotations

import argparse
import random
import sys
from pathlib import Path

import sympy as sp
import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "generator"))
from dyngen.emission.opcount import count_all  # noqa: E402


def modified_dh(path: Path) -> tuple[list, float]:
    """(alpha_j, d_j, r_j) per joint in Khalil's modified DH, and |g| along -z0. A standard-DH
    table moves by one row: alpha_j = alpha'_{j-1}, d_j = a'_{j-1}, r_j = d'_j."""
    arm = yaml.safe_load(path.read_text())
    assert all(j["type"] == "revolute" for j in arm["joints"]) and arm["gravity"][:2] == [0, 0]
    rows = [(sp.sympify(j["alpha"]), sp.nsimplify(j["a"]), sp.nsimplify(j["d"])) for j in arm["joints"]]
    if arm["dh"] == "standard":
        rows = [(rows[k - 1][0] if k else 0, rows[k - 1][1] if k else 0, rows[k][2]) for k in range(len(rows))]
    return rows, -arm["gravity"][2]


class Symbols:
    """SYMORO's SymbolManager.replace: an element that is not an atom becomes a symbol; the same
    expression (or its negative) again is the same symbol."""

    def __init__(self):
        self.equations, self.known = [], {}

    def element(self, e, name):
        if e.is_Atom or (-e).is_Atom:
            return e
        for sign in (1, -1):
            if sign * e in self.known:
                return sign * self.known[sign * e]
        s = sp.Symbol(name)
        self.known[e] = s
        self.equations.append((s, e))
        return s

    def matrix(self, M, name):
        return sp.Matrix(M.shape[0], M.shape[1], lambda i, k: self.element(M[i, k], f"{name}{i + 1}{k + 1}"))


def skew(v):
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def grouped_links(n):
    """(J, MS, M) per link over Khalil's grouped parameters of a revolute chain."""
    links = [(sp.diag(0, 0, sp.Symbol("ZZR1")), sp.zeros(3, 1), 0)]
    for j in range(2, n + 1):
        XX, XY, XZ, YZ, ZZ, MX, MY = (sp.Symbol(f"{k}{j}") for k in ("XXR", "XY", "XZ", "YZ", "ZZR", "MX", "MY"))
        links.append((sp.Matrix([[XX, XY, XZ], [XY, 0, YZ], [XZ, YZ, ZZ]]), sp.Matrix([MX, MY, 0]), 0))
    return links


def standard_links(n):
    links = []
    for j in range(1, n + 1):
        XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M = (sp.Symbol(f"{k}{j}") for k in
                                                  ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"))
        links.append((sp.Matrix([[XX, XY, XZ], [XY, YY, YZ], [XZ, YZ, ZZ]]), sp.Matrix([MX, MY, MZ]), M))
    return links


def newton_euler(rows, g, links):
    """(torques, the equations they read): fixed_inverse_dynmodel of SYMORO, element by element."""
    n, symbols, z = len(rows), Symbols(), sp.Matrix([0, 0, 1])
    qd = [sp.Symbol(f"QP{j}") for j in range(1, n + 1)]
    qdd = [sp.Symbol(f"QDP{j}") for j in range(1, n + 1)]
    R, P = [], []  # ^{j-1}R_j, ^{j-1}P_j
    for j, (alpha, d, r) in enumerate(rows):
        C, S, ca, sa = sp.Symbol(f"C{j + 1}"), sp.Symbol(f"S{j + 1}"), sp.cos(alpha), sp.sin(alpha)
        R.append(sp.Matrix([[C, -S, 0], [ca * S, ca * C, -sa], [sa * S, sa * C, ca]]))
        P.append(sp.Matrix([d, -r * sa, r * ca]))
    w, wd, vd, U = sp.zeros(3, 1), sp.zeros(3, 1), sp.Matrix([0, 0, g]), sp.zeros(3, 3)
    motion = []
    for j in range(n):
        jRi = R[j].T
        wi = symbols.matrix(jRi * w, f"WI{j + 1}")
        w_new = symbols.matrix(wi + qd[j] * z, f"W{j + 1}")
        wd = symbols.matrix(jRi * wd + qdd[j] * z + skew(wi) * (qd[j] * z), f"WP{j + 1}")
        vd = symbols.matrix(jRi * (vd + U * P[j]), f"VP{j + 1}")
        w = w_new
        U = symbols.matrix(skew(wd) + skew(w) * skew(w), f"U{j + 1}")
        motion.append((w, wd, vd, U))
    forces = []
    for j, ((J, MS, M), (w, wd, vd, U)) in enumerate(zip(links, motion)):
        F = symbols.matrix(M * vd + U * MS, f"F{j + 1}")
        psi = symbols.matrix(J * w, f"PSI{j + 1}")
        forces.append((F, symbols.matrix(J * wd + skew(w) * psi, f"No{j + 1}")))
    f, m, tau = None, None, [None] * n
    for j in reversed(range(n)):
        F, N = forces[j]
        fj, nj = F, N + skew(links[j][1]) * motion[j][2]
        if f is not None:
            fdi = symbols.matrix(R[j + 1] * f, f"FDI{j + 2}")
            fj, nj = fj + fdi, nj + R[j + 1] * m + skew(P[j + 1]) * fdi
        f, m = symbols.matrix(fj, f"E{j + 1}"), symbols.matrix(nj, f"N{j + 1}")
        tau[j] = m[2]
    definitions, read = dict(symbols.equations), set()
    stack = [s for t in tau for s in sp.sympify(t).free_symbols if s in definitions]
    while stack:  # what the torques read, and nothing else
        s = stack.pop()
        if s not in read:
            read.add(s)
            stack.extend(x for x in definitions[s].free_symbols if x in definitions)
    return tau, [(s, e) for s, e in symbols.equations if s in read]


def check(rows, g, name):
    """The recursion over standard parameters against dyngen's rnea, 3 random states."""
    from dyngen.derivation.models import Derivation
    from dyngen.derivation.evaluate import evaluate
    from dyngen.description import load_robot
    import numpy as np
    robot = load_robot(ROOT / "examples" / f"{name}.yaml")
    assert yaml.safe_load((ROOT / "examples" / f"{name}.yaml").read_text())["dh"] == "modified"
    n = len(rows)
    tau, equations = newton_euler(rows, g, standard_links(n))
    rnea = Derivation(robot).rnea()
    rng, worst = random.Random(3), 0.0
    for _ in range(3):
        q, qd, qdd = ([rng.uniform(-2, 2) for _ in range(n)] for _ in range(3))
        s = [rng.uniform(0.1, 1) for _ in range(10 * n)]
        values = {}
        for j in range(n):
            values.update({sp.Symbol(f"C{j + 1}"): np.cos(q[j]), sp.Symbol(f"S{j + 1}"): np.sin(q[j]),
                           sp.Symbol(f"QP{j + 1}"): qd[j], sp.Symbol(f"QDP{j + 1}"): qdd[j]})
            for k, key in enumerate(("M", "MX", "MY", "MZ", "XX", "XY", "XZ", "YY", "YZ", "ZZ")):
                values[sp.Symbol(f"{key}{j + 1}")] = s[10 * j + k]  # dyngen's standard order per link
        for sym, e in equations:
            values[sym] = float(e.xreplace(values))
        mine = np.array([float(sp.sympify(t).xreplace(values)) for t in tau])
        want = np.asarray(evaluate(rnea, robot.joint_models, {"q": q, "qd": qd, "qdd": qdd, "s": s}), dtype=float)
        worst = max(worst, float(np.max(np.abs(mine - want)) / np.max(np.abs(want))))
    print(f"{name}: the recursion over the standard parameters against dyngen's rnea: {worst:.1e}")
    assert worst < 1e-9, worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--arms", nargs="+", default=["lwr", "rx90"])
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    for name in args.arms:
        rows, g = modified_dh(ROOT / "examples" / f"{name}.yaml")
        if args.check:
            check(rows, g, name)
        tau, equations = newton_euler(rows, g, grouped_links(len(rows)))
        ops = count_all([e for _, e in equations] + tau)
        print(f"{name}: Khalil's customised Newton-Euler, {1 + 7 * (len(rows) - 1)} general base coefficients: "
              f"{ops.mul} multiplications, {ops.add} additions ({len(equations)} equations)")


if __name__ == "__main__":
    main()
