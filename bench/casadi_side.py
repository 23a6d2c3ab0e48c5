"""The CasADi competitor of bench_dynamics.py: a plain recursive Newton-Euler over casadi.SX,
code-generated to C, as a careful CasADi user would write it.

The arm is the Pinocchio model of the benchmark (tests/oracles/pinocchio_arm.py): per joint a
placement (R, t) in the parent joint's frame, a rotation (RZ) or translation (PZ) about the
local z, and the body's inertia in the joint frame. Rotation entries within 1e-12 of 0 or +-1
are written as exact 0 and +-1 (what a user writing cos(pi/2) as 0 does), so that CasADi drops
the products with them. Two variants, both code-generated with cse=True:

    <arm>_cas_<fn>        the link parameters are an input: Pinocchio's dynamic parameters,
                          10 per body [m, m c, I about the joint origin (xx, xy, yy, xz, yz, zz)]
    <arm>_casb_<fn>       the same with the parameters baked in as numbers

fn: rnea(q, qd, qdd[, params]), gravity(q[, params]) = rnea(q, 0, 0), mass_matrix(q[, params])
= d rnea(q, 0, qdd; no gravity) / d qdd (casadi.jacobian), full n x n, row-major as dyngen's.
"""
from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np

VARIANTS = ("cas", "casb")
FUNCTIONS = ("rnea", "gravity", "mass_matrix")


def _clean(x: float) -> float:
    for exact in (0.0, 1.0, -1.0):
        if abs(x - exact) < 1e-12:
            return exact
    return float(x)


def _cross(a, b):
    return ca.vertcat(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _joints(model):
    out = []
    for j in range(1, model.njoints):
        kind = model.joints[j].shortname()
        M = model.jointPlacements[j]
        R = ca.DM([[_clean(v) for v in row] for row in np.asarray(M.rotation)])
        t = ca.DM([_clean(v) for v in np.asarray(M.translation)])
        out.append((kind == "JointModelRZ", R, t))
    return out


def rnea(model, q, qd, qdd, params, gravity):
    """tau of the plain recursion (SX); params: 10 per body, Pinocchio's dynamic parameters."""
    joints = _joints(model)
    n = len(joints)
    z = ca.DM([0, 0, 1])
    w, wd, a = ca.SX.zeros(3), ca.SX.zeros(3), -ca.SX(ca.DM(list(gravity)))
    frames, wrenches = [], []
    for i, (revolute, R0, t) in enumerate(joints):
        if revolute:
            c, s = ca.cos(q[i]), ca.sin(q[i])
            Rq = ca.vertcat(ca.horzcat(c, -s, 0), ca.horzcat(s, c, 0), ca.horzcat(0, 0, 1))
            R, p = ca.mtimes(R0, Rq), t
        else:
            R, p = R0, t + ca.mtimes(R0, z) * q[i]
        E = R.T
        w_in = ca.mtimes(E, w)
        a_i = ca.mtimes(E, a + _cross(wd, p) + _cross(w, _cross(w, p)))
        wd_i = ca.mtimes(E, wd)
        if revolute:
            w_i = w_in + z * qd[i]
            wd_i = wd_i + _cross(w_in, z * qd[i]) + z * qdd[i]
        else:
            w_i = w_in
            a_i = a_i + 2 * _cross(w_i, z * qd[i]) + z * qdd[i]
        w, wd, a = w_i, wd_i, a_i
        m, h = params[10 * i], params[10 * i + 1:10 * i + 4]
        xx, xy, yy, xz, yz, zz = (params[10 * i + k] for k in range(4, 10))
        inertia = ca.vertcat(ca.horzcat(xx, xy, xz), ca.horzcat(xy, yy, yz), ca.horzcat(xz, yz, zz))
        F = m * a + _cross(wd, h) + _cross(w, _cross(w, h))
        N = ca.mtimes(inertia, wd) + _cross(w, ca.mtimes(inertia, w)) + _cross(h, a)
        frames.append((revolute, R, p))
        wrenches.append((F, N))
    tau = [None] * n
    f, nm = ca.SX.zeros(3), ca.SX.zeros(3)
    for i in reversed(range(n)):
        F, N = wrenches[i]
        if i + 1 < n:
            _, Rc, pc = frames[i + 1]
            fc = ca.mtimes(Rc, f)
            f, nm = F + fc, N + ca.mtimes(Rc, nm) + _cross(pc, fc)
        else:
            f, nm = F, N
        tau[i] = nm[2] if frames[i][0] else f[2]
    return ca.vertcat(*tau)


def body_parameters(model) -> np.ndarray:
    return np.concatenate([np.asarray(model.inertias[j].toDynamicParameters()).ravel()
                           for j in range(1, model.njoints)])


def functions(model, name: str) -> list:
    """The six casadi.Function objects of one arm (both variants, three functions)."""
    n = model.nv
    q, qd, qdd = ca.SX.sym("q", n), ca.SX.sym("qd", n), ca.SX.sym("qdd", n)
    params = ca.SX.sym("params", 10 * n)
    baked = ca.SX(ca.DM(body_parameters(model)))
    gravity = np.asarray(model.gravity.linear, dtype=float)
    zero = ca.SX.zeros(n)
    out = []
    for variant, P in (("cas", params), ("casb", baked)):
        extra = [params] if variant == "cas" else []
        tau = rnea(model, q, qd, qdd, P, gravity)
        g = rnea(model, q, zero, zero, P, gravity)
        M = ca.jacobian(rnea(model, q, zero, qdd, P, [0.0, 0.0, 0.0]), qdd)
        M_rows = ca.reshape(M.T, n * n, 1)  # row-major
        opts = {"cse": True}
        out.append(ca.Function(f"{name}_{variant}_rnea", [q, qd, qdd, *extra], [tau], opts))
        out.append(ca.Function(f"{name}_{variant}_gravity", [q, *extra], [g], opts))
        out.append(ca.Function(f"{name}_{variant}_mass_matrix", [q, *extra], [ca.densify(M_rows)], opts))
    return out


def generate(model, name: str, folder: Path) -> dict:
    """Writes <name>_casadi.c and .h into folder; returns {function name: (sz_iw, sz_w)} and
    the SX operation counts {function name: n_instructions}."""
    fns = functions(model, name)
    cg = ca.CodeGenerator(f"{name}_casadi.c", {"with_header": True, "casadi_real": "double"})
    for f in fns:
        cg.add(f)
    cwd = Path.cwd()
    folder.mkdir(parents=True, exist_ok=True)
    cg.generate(str(folder) + "/")
    del cwd
    return {f.name(): {"iw": int(f.sz_iw()), "w": int(f.sz_w()), "n_instructions": int(f.n_instructions())}
            for f in fns}


# --- the controller functions (bench_controller.py) ---------------------------------------------
# Written the way a careful CasADi user would, from the same plain rnea above:
#   coriolis         C_ij = sum_k 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) qd_k (Christoffel, from
#                    casadi.jacobian of M)
#   mass_matrix_dot  casadi.jtimes(M, q, qd) (forward mode along qd)
#   slotine_li       casadi.jacobian(M qr_dd + C qr_d + g, params) (parameters as input only: Y holds none)
#   fd               casadi.solve(M, tau - rnea(q, qd, 0)) (CasADi's symbolic QR)
#   rnea_derivatives casadi.jacobian(rnea, [q; qd])
#   fd_derivatives   casadi.jacobian(fd, [q; qd])
# Every matrix output is row-major, as dyngen's.
CONTROLLER_FUNCTIONS = {  # name -> (inputs, output)
    "coriolis": (["q", "qd"], "C"),
    "mass_matrix_dot": (["q", "qd"], "Md"),
    "slotine_li": (["q", "qd", "qrd", "qrdd"], "Y"),
    "fd": (["q", "qd", "tau"], "qdd"),
    "rnea_derivatives": (["q", "qd", "qdd"], "D"),
    "fd_derivatives": (["q", "qd", "tau"], "D"),
}


def _row_major(X):
    return ca.densify(ca.reshape(X.T, X.numel(), 1))


def _christoffel(M, q, qd, n: int):
    dM = ca.jacobian(ca.reshape(M, n * n, 1), q)  # row j + n i of column k: dM_ji / dq_k
    C = ca.SX.zeros(n, n)
    for i in range(n):
        for j in range(n):
            C[i, j] = sum(0.5 * (dM[i + n * j, k] + dM[i + n * k, j] - dM[j + n * k, i]) * qd[k] for k in range(n))
    return C


def controller_functions(model, name: str, which=tuple(CONTROLLER_FUNCTIONS)) -> list:
    """The controller casadi.Function objects of one arm: both variants of every function in
    `which` but slotine_li, which has only the parameters-as-input one (<name>_cas_slotine_li).
    bench_dynamics.py asks for ("fd",) alone: the same functions, so the same C and cached objects."""
    n = model.nv
    sym = {x: ca.SX.sym(x, n) for x in ("q", "qd", "qdd", "tau", "qrd", "qrdd")}
    q, qd = sym["q"], sym["qd"]
    params = ca.SX.sym("params", 10 * n)
    gravity = np.asarray(model.gravity.linear, dtype=float)
    zero = ca.SX.zeros(n)
    opts = {"cse": True}
    out = []
    for variant, P in (("cas", params), ("casb", ca.SX(ca.DM(body_parameters(model))))):
        extra = [params] if variant == "cas" else []
        M = ca.jacobian(rnea(model, q, zero, sym["qdd"], P, [0.0, 0.0, 0.0]), sym["qdd"])
        C = _christoffel(M, q, qd, n) if {"coriolis", "slotine_li"} & set(which) else None
        bias = rnea(model, q, qd, zero, P, gravity)
        qdd = ca.solve(M, sym["tau"] - bias)
        x = ca.vertcat(q, qd)
        outputs = {"coriolis": lambda: _row_major(C), "mass_matrix_dot": lambda: _row_major(ca.jtimes(M, q, qd)),
                   "fd": lambda: qdd,
                   "rnea_derivatives": lambda: _row_major(ca.jacobian(rnea(model, q, qd, sym["qdd"], P, gravity), x)),
                   "fd_derivatives": lambda: _row_major(ca.jacobian(qdd, x))}
        if variant == "cas":
            g = rnea(model, q, zero, zero, P, gravity)
            outputs["slotine_li"] = lambda: _row_major(
                ca.jacobian(ca.mtimes(M, sym["qrdd"]) + ca.mtimes(C, sym["qrd"]) + g, params))
        for fn in CONTROLLER_FUNCTIONS:  # the dict's order, whatever the order of `which`
            if fn not in which or fn not in outputs:
                continue
            ins = [sym[i] for i in CONTROLLER_FUNCTIONS[fn][0]]
            out.append(ca.Function(f"{name}_{variant}_{fn}", ins + extra, [outputs[fn]()], opts))
    return out


def generate_controller(model, name: str, folder: Path, cc: str, flags: list,
                        which=tuple(CONTROLLER_FUNCTIONS)) -> dict:
    """One C file per controller function in folder, each compiled (or found in the private
    cache: casadi_objects.py); returns {function name: {iw, w, n_instructions, header, object}}."""
    import casadi_objects

    fns = controller_functions(model, name, which)
    built = casadi_objects.compile_functions(fns, folder, cc, flags)
    return {k: {**v, "header": built[k][0], "object": built[k][1]} for k, v in casadi_objects.info(fns).items()}


# --- the kinematics functions (bench_kinematics.py) ---------------------------------------------
# Forward kinematics over casadi.SX from the same Pinocchio model, the link frames at the given
# placements after each joint (`posts`, Pinocchio frames) and the flange at the last link frame
# times the tool; as a careful user writes them: the flange Jacobian's linear rows by
# casadi.jacobian of its origin, its angular rows the joint axes in the base frame (zero for a
# slide); Jdot qd = casadi.jtimes(J qd, q, qd) (qdd = 0). Outputs row-major as dyngen's.
KINEMATICS_FUNCTIONS = {"link_poses": ["q"], "flange_pose": ["q"], "jacobian": ["q"], "link_jacobians": ["q"],
                        "jacobian_dot_qd": ["q", "qd"]}


def _homogeneous(R, p):
    return ca.vertcat(ca.horzcat(R, p), ca.DM([[0, 0, 0, 1]]))


def _exact(T) -> ca.DM:
    return ca.DM([[_clean(v) for v in row] for row in np.asarray(T)])


def kinematics_functions(model, name: str, posts, tool) -> list:
    """posts[i]: link frame i in joint i's frame (4x4); tool: the flange in the last link frame."""
    n = model.nv
    q, qd = ca.SX.sym("q", n), ca.SX.sym("qd", n)
    T = ca.SX.eye(4)
    links, axes, origins = [], [], []
    for i, (revolute, R0, t) in enumerate(_joints(model)):
        T = ca.mtimes(T, _homogeneous(R0, t))
        if revolute:
            c, s = ca.cos(q[i]), ca.sin(q[i])
            T = ca.mtimes(T, _homogeneous(ca.vertcat(ca.horzcat(c, -s, 0), ca.horzcat(s, c, 0), ca.horzcat(0, 0, 1)),
                                          ca.DM.zeros(3)))
        else:
            T = ca.mtimes(T, _homogeneous(ca.DM.eye(3), ca.vertcat(0, 0, q[i])))
        axes.append(T[:3, 2] if revolute else ca.DM.zeros(3))
        links.append(ca.mtimes(T, _exact(posts[i])))
    flange = ca.mtimes(links[-1], _exact(tool))

    def jacobian_of(origin, upto):
        angular = ca.horzcat(*(axes[j] if j <= upto else ca.DM.zeros(3) for j in range(n)))
        return ca.vertcat(ca.jacobian(origin, q), angular)

    J = jacobian_of(flange[:3, 3], n - 1)
    outputs = {"link_poses": ca.vertcat(*(_row_major(L) for L in links)), "flange_pose": _row_major(flange),
               "jacobian": _row_major(J),
               "link_jacobians": ca.vertcat(*(_row_major(jacobian_of(L[:3, 3], i)) for i, L in enumerate(links))),
               "jacobian_dot_qd": ca.densify(ca.jtimes(ca.mtimes(J, qd), q, qd))}
    syms = {"q": q, "qd": qd}
    return [ca.Function(f"{name}_casb_{fn}", [syms[x] for x in KINEMATICS_FUNCTIONS[fn]], [value], {"cse": True})
            for fn, value in outputs.items()]


def generate_kinematics(model, name: str, posts, tool, folder: Path, cc: str, flags: list) -> dict:
    """One C file per kinematics function in folder, each compiled (or found in the private
    cache); returns {function name: {iw, w, n_instructions, header, object}}."""
    import casadi_objects

    fns = kinematics_functions(model, name, posts, tool)
    built = casadi_objects.compile_functions(fns, folder, cc, flags)
    return {k: {**v, "header": built[k][0], "object": built[k][1]} for k, v in casadi_objects.info(fns).items()}
