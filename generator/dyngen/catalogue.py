"""The function catalogue: every C function dyngen emits for a robot, written down once.

Each entry says what the function is (its derivation model), its arguments and output with
their shapes, the Eigen type of the output in <robot>.hpp and how <robot>_selftest.c checks
it. Rendering (emission/render.py), the C++ header (emission/eigen.py), the self-test and the
manifest derive from it; code that calls the generated functions (identification,
validation, diagnosis) takes their names from here. The C name is <robot>_<name>.

Shapes are tuples of dimension names, resolved per robot by `dimensions`:
dof (N), state (2 N: q and qd), parameters (10 N), stacked (N(N+1)/2), gravity_symbols, friction,
pi_<kind> (the number of base coefficients of a kind), homogeneous (4), twist (6),
link_pose_rows (4 N) and link_twist_rows (6 N).
"""

from __future__ import annotations

from dataclasses import dataclass

from .parameters import PER_LINK
from .terms.friction import FRICTION_NAMES

KINDS = ("gravity", "inertia", "full")
KIND_LABELS = {"gravity": "gravity vector g(q) = Y_g(q) pi_gravity",
               "inertia": "stacked inertia matrix m~(q) = Y_m(q) pi_inertia",
               "full": "inverse dynamics tau = Y(q, qd, qdd) pi_full"}
FRICTION_PER_JOINT = len(FRICTION_NAMES)  # the friction terms' fields (terms/friction.py)


@dataclass(frozen=True)
class Argument:
    shape: tuple  # dimension names
    meaning: str
    eigen: str  # the Eigen type of <robot>.hpp


ARGUMENTS = {
    "q": Argument(("dof",), "joint positions [rad or m]", "Joints"),
    "qd": Argument(("dof",), "joint velocities", "Joints"),
    "qdd": Argument(("dof",), "joint accelerations", "Joints"),
    "p": Argument(("parameters",), "dynamic parameters, 10 per link", "Parameters"),
    "s": Argument(("parameters",), "standard parameters, 10 per link (docs/conventions.md)", "Parameters"),
    "gravity": Argument(("gravity_symbols",), "gravity symbols", "GravitySymbols"),  # only when gravity has symbols
    "f": Argument(("friction",), "per joint " + ", ".join(FRICTION_NAMES), "Friction"),
    "pi_full": Argument(("pi_full",), "base coefficients pi_full (e.g. identified; from p: pi_full())", "PiFull"),
    "qr_d": Argument(("dof",), "reference velocities (Slotine-Li: qd_d - Lambda e)", "Joints"),
    "qr_dd": Argument(("dof",), "reference accelerations (Slotine-Li: qdd_d - Lambda e_dot)", "Joints"),
    "tau": Argument(("dof",), "joint torques/forces", "Joints"),
}


@dataclass(frozen=True)
class Output:
    name: str  # the C argument written
    shape: tuple  # dimension names
    meaning: str
    eigen: str  # the Eigen type of <robot>.hpp


@dataclass(frozen=True)
class Check:
    """How the self-test checks a function: its output (times the output of `times`, for a
    regressor) against the values embedded for function `expected` (its own when empty);
    `stacked`: compared with the upper triangle of a square expected matrix, row by row;
    `size`: a regressor whose |Y| |pi| (with its coefficients) sizes the error instead of the
    expected values (a sum over base coefficients can cancel in float)."""

    expected: str = ""
    times: str = ""
    stacked: bool = False
    size: str = ""


@dataclass(frozen=True)
class Function:
    name: str
    source: str  # the C file <robot>_<source>.c
    model: str  # what it is printed from (Derivation's method, or "template" for friction.c.j2)
    inputs: tuple  # argument names (ARGUMENTS), in order; "gravity" only when gravity has symbols
    output: Output
    doc: str
    check: Check
    kind: str = ""  # gravity | inertia | full, for coefficient and regressor functions
    state: bool = True  # whether it reads a joint state (checked at every self-test state)
    more: tuple = ()  # further Outputs, written by the same call after `output`

    @property
    def outputs(self) -> tuple:
        return (self.output, *self.more)

    def arguments(self, gravity_symbols: bool) -> tuple:
        return tuple(a for a in self.inputs if a != "gravity" or gravity_symbols)

    @property
    def expected(self) -> str:
        return self.check.expected or self.name


def _coefficients(kind: str) -> tuple[Function, Function]:
    pi = Function(f"pi_{kind}", "parameters", "coefficients", ("p",),
                  Output("pi", (f"pi_{kind}",), f"pi_{kind}", f"Pi{kind.capitalize()}"),
                  f"Base coefficients pi_{kind}(p) of the {KIND_LABELS[kind]}.", Check(), kind, state=False)
    jacobian = Function(f"pi_{kind}_jacobian", "parameters", "coefficient_jacobian", ("p",),
                        Output("J", (f"pi_{kind}", "parameters"), "row-major", f"Pi{kind.capitalize()}Jacobian"),
                        f"Jacobian d pi_{kind} / d p (for gradient-based extraction).", Check(), kind, state=False)
    return pi, jacobian


STANDARD_FROM_DYNAMIC = Function(
    "standard_from_dynamic", "parameters", "standard_from_dynamic", ("p",),
    Output("s", ("parameters",), "standard parameters", "Parameters"),
    "Standard parameters s from dynamic parameters p.", Check(), state=False)
PI_GRAVITY, PI_GRAVITY_JACOBIAN = _coefficients("gravity")
PI_INERTIA, PI_INERTIA_JACOBIAN = _coefficients("inertia")
PI_FULL, PI_FULL_JACOBIAN = _coefficients("full")
REGRESSOR_GRAVITY = Function(
    "regressor_gravity", "regressors", "regressor", ("q", "gravity"),
    Output("Y", ("dof", "pi_gravity"), "row-major", "RegressorGravity"),
    f"Base regressor of the {KIND_LABELS['gravity']}.", Check("gravity", times="pi_gravity"), "gravity")
REGRESSOR_INERTIA = Function(
    "regressor_inertia", "regressors", "unit_accelerations", ("q",),
    Output("Y", ("stacked", "pi_inertia"), "row-major", "RegressorInertia"),
    f"Base regressor of the {KIND_LABELS['inertia']}.", Check("mass_matrix", times="pi_inertia", stacked=True),
    "inertia")
REGRESSOR = Function(
    "regressor", "regressors", "regressor", ("q", "qd", "qdd", "gravity"),
    Output("Y", ("dof", "pi_full"), "row-major", "Regressor"),
    f"Base regressor of the {KIND_LABELS['full']}.", Check("rnea", times="pi_full"), "full")
RNEA = Function(
    "rnea", "dynamics", "rnea", ("q", "qd", "qdd", "s", "gravity"),
    Output("tau", ("dof",), "joint torques/forces", "Joints"),
    "Inverse dynamics tau = M(q) qdd + c(q, qd) + g(q), recursive Newton-Euler.", Check())
RNEA_NOMINAL = Function(
    "rnea_nominal", "dynamics", "rnea_nominal", ("q", "qd", "qdd", "gravity"),
    Output("tau", ("dof",), "joint torques/forces", "Joints"),
    "Inverse dynamics as rnea at the description's nominal parameters, folded in as numbers (the self-test's "
    "fixed parameters when it has none; manifest.json selftest.p).", Check("rnea"))
GRAVITY = Function(
    "gravity", "dynamics", "gravity", ("q", "s", "gravity"),
    Output("g", ("dof",), "gravity torques", "Joints"), "Gravity vector g(q).", Check())
MASS_MATRIX = Function(
    "mass_matrix", "dynamics", "mass_matrix", ("q", "s"),
    Output("M", ("dof", "dof"), "row-major, symmetric", "MassMatrix"), "Inertia matrix M(q).", Check())
INVERSE_DYNAMICS = Function(
    "inverse_dynamics", "dynamics", "inverse_dynamics", ("q", "qd", "qdd", "pi_full", "gravity"),
    Output("tau", ("dof",), "joint torques/forces", "Joints"),
    "Inverse dynamics tau = Y(q, qd, qdd) pi_full from the base coefficients, a Newton-Euler recursion in the "
    "grouped parameters (for controllers that hold identified coefficients).", Check("rnea", size="regressor"))
FRICTION = Function(
    "friction", "friction", "template", ("qd", "f"),
    Output("tau", ("dof",), "friction torques", "Joints"),
    "Joint friction (Coulomb, viscous, Stribeck, direction), the terms of terms/friction.py.", Check())

# ---- kinematics (derivation/kinematics_functions.py): base frame, rows [v; w] ---------------
LINK_POSES = Function(
    "link_poses", "kinematics", "link_poses", ("q",),
    Output("T", ("link_pose_rows", "homogeneous"), "row-major 4x4 pose of link frame i in rows 4(i-1)..4i-1",
           "LinkPoses"),
    "Pose of every link frame in the base frame: 4x4 homogeneous matrices [R p; 0 0 0 1], link 1 first.", Check())
FLANGE_POSE = Function(
    "flange_pose", "kinematics", "flange_pose", ("q",),
    Output("T", ("homogeneous", "homogeneous"), "row-major 4x4 [R p; 0 0 0 1]", "Pose"),
    "Pose of the flange frame (last link frame times the description's tool offset) in the base frame.", Check())
JACOBIAN = Function(
    "jacobian", "kinematics", "jacobian", ("q",),
    Output("J", ("twist", "dof"), "row-major, rows [v; w]", "Jacobian"),
    "Geometric Jacobian of the flange in the base frame: [v; w] = J qd, v the velocity of the flange origin, "
    "w the angular velocity (Pinocchio's LOCAL_WORLD_ALIGNED).", Check())
LINK_JACOBIANS = Function(
    "link_jacobians", "kinematics", "link_jacobians", ("q",),
    Output("J", ("link_twist_rows", "dof"), "row-major, rows 6(i-1)..6i-1: link i's [v; w]", "LinkJacobians"),
    "Geometric Jacobian of every link frame's origin in the base frame, rows [v; w] per link, link 1 first "
    "(columns of the joints after link i are zero).", Check())
JACOBIAN_DOT_QD = Function(
    "jacobian_dot_qd", "kinematics", "jacobian_dot_qd", ("q", "qd"),
    Output("jdot_qd", ("twist",), "[linear; angular] acceleration at qdd = 0", "Twist"),
    "Jdot qd of the flange in the base frame: the classical acceleration of the flange origin and the angular "
    "acceleration at qdd = 0, so that [a; wd] = J qdd + Jdot qd (operational-space control).", Check())

# ---- one call per control cycle (derivation/control.py): one program, several outputs ------
_CONTROL_OUTPUTS = (Output("M", ("dof", "dof"), "inertia matrix, row-major, symmetric", "MassMatrix"),
                    Output("c", ("dof",), "velocity torques c(q, qd) = rnea(q, qd, 0) - g(q)", "Joints"))
CONTROL = Function(
    "control", "control", "control", ("q", "qd", "s", "gravity"),
    Output("g", ("dof",), "gravity torques", "Joints"),
    "g(q), M(q) and c(q, qd) in one call (tau = M qdd + c + g): each sine and cosine once, shared subexpressions "
    "once.", Check(), more=_CONTROL_OUTPUTS)
CONTROL_WITH_JACOBIAN = Function(
    "control_with_jacobian", "control", "control_with_jacobian", ("q", "qd", "s", "gravity"),
    Output("g", ("dof",), "gravity torques", "Joints"),
    "control() and the flange's Jacobian J and Jdot qd (as jacobian and jacobian_dot_qd) in one call.", Check(),
    more=_CONTROL_OUTPUTS + (Output("J", ("twist", "dof"), "flange Jacobian, row-major, rows [v; w]", "Jacobian"),
                             Output("jdot_qd", ("twist",), "Jdot qd of the flange", "Twist")))

CORIOLIS_MATRIX = Function(
    "coriolis_matrix", "coriolis", "coriolis_matrix", ("q", "qd", "s"),
    Output("C", ("dof", "dof"), "row-major", "JointMatrix"),
    "Coriolis matrix C(q, qd) of the Christoffel symbols: c = C qd, M_dot - 2C skew-symmetric.", Check())
MASS_MATRIX_DERIVATIVE = Function(
    "mass_matrix_derivative", "coriolis", "mass_matrix_derivative", ("q", "qd", "s"),
    Output("Mdot", ("dof", "dof"), "row-major, symmetric", "JointMatrix"),
    "Time derivative of the inertia matrix M_dot(q, qd) = C + C^T.", Check())
REGRESSOR_SLOTINE_LI = Function(
    "regressor_slotine_li", "regressors", "regressor_slotine_li", ("q", "qd", "qr_d", "qr_dd", "gravity"),
    Output("Y", ("dof", "pi_full"), "row-major", "Regressor"),
    "Slotine-Li regressor: Y(q, qd, qr_d, qr_dd) pi_full = M(q) qr_dd + C(q, qd) qr_d + g(q).",
    Check("rnea", times="pi_full"), "full")
FORWARD_DYNAMICS = Function(
    "forward_dynamics", "forward", "forward_dynamics", ("q", "qd", "tau", "s", "gravity"),
    Output("qdd", ("dof",), "joint accelerations", "Joints"),
    "Forward dynamics qdd = M(q)^-1 (tau - c(q, qd) - g(q)): the articulated-body algorithm or M = L D L^T, "
    "whichever has fewer operations for this arm (the source's section comments say which).", Check())
RNEA_DERIVATIVES = Function(
    "rnea_derivatives", "derivatives", "rnea_derivatives", ("q", "qd", "qdd", "s", "gravity"),
    Output("D", ("dof", "state"), "row-major, [d tau / d q | d tau / d qd]", "Derivatives"),
    "Derivatives of inverse dynamics: D = [d tau / d q | d tau / d qd] (N x 2N) at (q, qd, qdd).", Check())
FORWARD_DYNAMICS_DERIVATIVES = Function(
    "forward_dynamics_derivatives", "derivatives", "forward_dynamics_derivatives", ("q", "qd", "tau", "s", "gravity"),
    Output("D", ("dof", "state"), "row-major, [d qdd / d q | d qdd / d qd]", "Derivatives"),
    "Derivatives of forward dynamics: D = [d qdd / d q | d qdd / d qd] = -M^-1 [d tau / d q | d tau / d qd] "
    "at qdd = FD(q, qd, tau) (d qdd / d tau = M^-1).", Check())

FUNCTIONS = (STANDARD_FROM_DYNAMIC, PI_GRAVITY, PI_GRAVITY_JACOBIAN, PI_INERTIA, PI_INERTIA_JACOBIAN, PI_FULL,
             PI_FULL_JACOBIAN, REGRESSOR_GRAVITY, REGRESSOR_INERTIA, REGRESSOR, RNEA, RNEA_NOMINAL, GRAVITY, MASS_MATRIX,
             INVERSE_DYNAMICS, FRICTION, LINK_POSES, FLANGE_POSE, JACOBIAN, LINK_JACOBIANS, JACOBIAN_DOT_QD,
             CONTROL, CONTROL_WITH_JACOBIAN, CORIOLIS_MATRIX, MASS_MATRIX_DERIVATIVE,
             REGRESSOR_SLOTINE_LI, FORWARD_DYNAMICS, RNEA_DERIVATIVES, FORWARD_DYNAMICS_DERIVATIVES)
KINEMATICS = (LINK_POSES, FLANGE_POSE, JACOBIAN, LINK_JACOBIANS, JACOBIAN_DOT_QD)
BY_NAME = {f.name: f for f in FUNCTIONS}
COEFFICIENTS = {"gravity": PI_GRAVITY, "inertia": PI_INERTIA, "full": PI_FULL}
JACOBIANS = {"gravity": PI_GRAVITY_JACOBIAN, "inertia": PI_INERTIA_JACOBIAN, "full": PI_FULL_JACOBIAN}
REGRESSORS = {"gravity": REGRESSOR_GRAVITY, "inertia": REGRESSOR_INERTIA, "full": REGRESSOR}
SOURCES = {"parameters": "parameters and base coefficients", "regressors": "base regressors",
           "dynamics": "inverse dynamics, gravity and inertia matrix",
           "kinematics": "forward kinematics and Jacobians",
           "control": "one call per control cycle",
           "coriolis": "Coriolis matrix and inertia matrix derivative",
           "forward": "forward dynamics",
           "derivatives": "derivatives of inverse and forward dynamics"}  # straight-line C files, in order


def dimensions(dof: int, ranks: dict, gravity_symbols: int) -> dict:
    """Dimension name -> size for one robot; ranks: kind -> number of base coefficients."""
    return {"dof": dof, "state": 2 * dof, "parameters": PER_LINK * dof, "stacked": dof * (dof + 1) // 2,
            "gravity_symbols": gravity_symbols, "friction": FRICTION_PER_JOINT * dof,
            "homogeneous": 4, "twist": 6, "link_pose_rows": 4 * dof, "link_twist_rows": 6 * dof,
            **{f"pi_{kind}": rank for kind, rank in ranks.items()}}
