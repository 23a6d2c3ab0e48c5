"""The function catalogue: every C function dyngen emits for a robot, written down once.

Each entry says what the function is (its derivation model), its arguments and output with
their shapes, the Eigen type of the output in <robot>.hpp and how <robot>_selftest.c checks
it. Rendering (emission/render.py), the C++ header (emission/eigen.py), the self-test and the
manifest derive from it; code that calls the generated functions (identification,
validation, diagnosis) takes their names from here. The C name is <robot>_<name>.

Shapes are tuples of dimension names, resolved per robot by `dimensions`:
dof (N), state (2 N: q and qd), parameters (10 N), stacked (N(N+1)/2), gravity_symbols, friction (5 N) and
pi_<kind> (the number of base coefficients of a kind).
"""

from __future__ import annotations

from dataclasses import dataclass

from .parameters import PER_LINK

KINDS = ("gravity", "inertia", "full")
KIND_LABELS = {"gravity": "gravity vector g(q) = Y_g(q) pi_gravity",
               "inertia": "stacked inertia matrix m~(q) = Y_m(q) pi_inertia",
               "full": "inverse dynamics tau = Y(q, qd, qdd) pi_full"}
FRICTION_PER_JOINT = 5  # Fc, Fv, Fs, vs, eps (templates/friction.c.j2)


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
    "f": Argument(("friction",), "per joint Fc, Fv, Fs, vs, eps", "Friction"),
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
    `stacked`: compared with the upper triangle of a square expected matrix, row by row."""

    expected: str = ""
    times: str = ""
    stacked: bool = False


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
GRAVITY = Function(
    "gravity", "dynamics", "gravity", ("q", "s", "gravity"),
    Output("g", ("dof",), "gravity torques", "Joints"), "Gravity vector g(q).", Check())
MASS_MATRIX = Function(
    "mass_matrix", "dynamics", "mass_matrix", ("q", "s"),
    Output("M", ("dof", "dof"), "row-major, symmetric", "MassMatrix"), "Inertia matrix M(q).", Check())
FRICTION = Function(
    "friction", "friction", "template", ("qd", "f"),
    Output("tau", ("dof",), "friction torques", "Joints"),
    "Joint friction (Coulomb, viscous, Stribeck), templates/friction.c.j2.", Check())

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
    "Forward dynamics qdd = M(q)^-1 (tau - c(q, qd) - g(q)), M = L D L^T.", Check())
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
             PI_FULL_JACOBIAN, REGRESSOR_GRAVITY, REGRESSOR_INERTIA, REGRESSOR, RNEA, GRAVITY, MASS_MATRIX,
             FRICTION, CORIOLIS_MATRIX, MASS_MATRIX_DERIVATIVE, REGRESSOR_SLOTINE_LI,
             FORWARD_DYNAMICS, RNEA_DERIVATIVES, FORWARD_DYNAMICS_DERIVATIVES)
BY_NAME = {f.name: f for f in FUNCTIONS}
COEFFICIENTS = {"gravity": PI_GRAVITY, "inertia": PI_INERTIA, "full": PI_FULL}
JACOBIANS = {"gravity": PI_GRAVITY_JACOBIAN, "inertia": PI_INERTIA_JACOBIAN, "full": PI_FULL_JACOBIAN}
REGRESSORS = {"gravity": REGRESSOR_GRAVITY, "inertia": REGRESSOR_INERTIA, "full": REGRESSOR}
SOURCES = {"parameters": "parameters and base coefficients", "regressors": "base regressors",
           "dynamics": "inverse dynamics, gravity and inertia matrix",
           "coriolis": "Coriolis matrix and inertia matrix derivative",
           "forward": "forward dynamics",
           "derivatives": "derivatives of inverse and forward dynamics"}  # straight-line C files, in order


def dimensions(dof: int, ranks: dict, gravity_symbols: int) -> dict:
    """Dimension name -> size for one robot; ranks: kind -> number of base coefficients."""
    return {"dof": dof, "state": 2 * dof, "parameters": PER_LINK * dof, "stacked": dof * (dof + 1) // 2,
            "gravity_symbols": gravity_symbols, "friction": FRICTION_PER_JOINT * dof,
            **{f"pi_{kind}": rank for kind, rank in ranks.items()}}
