"""The Eigen types of the generated functions' arguments, for the C++ header <robot>.hpp.

Every flat C array gets a fixed-size Eigen type with the same memory layout, so a wrapper
can hand the caller's storage to the C function unchanged: vectors are column vectors,
matrices row-major (the C layout).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..catalogue import ARGUMENTS, FRICTION_PER_JOINT, FUNCTIONS
from ..terms.friction import FRICTION_NAMES

TYPE_DOCS = {
    "Joints": "one entry per joint: q, qd, qdd, tau, g",
    "Parameters": "10 per link, link 1 first: p (dynamic) or s (standard)",
    "GravitySymbols": "values of the gravity symbols, in the header's order",
    "MassMatrix": "M(q), symmetric",
    "RegressorGravity": "Y_g(q): g = Y_g pi_gravity",
    "RegressorInertia": "Y_m(q): row k is entry k of the stacked upper triangle of M (M11, M12, ..., MNN)",
    "Regressor": "Y(q, qd, qdd): tau = Y pi_full",
    "Friction": f"friction values, {FRICTION_PER_JOINT} per joint: " + ", ".join(FRICTION_NAMES),
    "Pose": "4x4 homogeneous pose [R p; 0 0 0 1] in the base frame",
    "LinkPoses": "the 4x4 pose of every link frame stacked, link 1 first",
    "Jacobian": "geometric Jacobian, rows [v; w] in the base frame",
    "LinkJacobians": "the Jacobian of every link frame's origin stacked, link 1 first",
    "Twist": "[linear; angular] in the base frame",
    "JointMatrix": "N x N, row-major: C(q, qd), M_dot(q, qd)",
    "Derivatives": "N x 2N, row-major: [d / d q | d / d qd] of tau or qdd",
}


@dataclass
class EigenType:
    name: str
    rows: int
    cols: int

    @property
    def doc(self) -> str:
        if self.name in TYPE_DOCS:
            return TYPE_DOCS[self.name]
        if self.name.endswith("Jacobian"):
            return "d pi / d p: row = base coefficient, column = entry of p"
        return "base coefficients"  # PiGravity, PiInertia, PiFull

    @property
    def options(self) -> str:
        # Eigen wants column vectors column-major and row vectors row-major; matrices follow C.
        return "Eigen::RowMajor" if self.cols > 1 else "Eigen::ColMajor"


@dataclass
class Wrapper:
    name: str  # C++ name, without the robot prefix
    c_name: str
    doc: str
    inputs: list  # (argument name, EigenType name)
    output: tuple  # (argument name, EigenType name)
    more: list  # further outputs (argument name, EigenType name): then only the form that writes into arguments

    @property
    def outputs(self) -> list:
        return [self.output, *self.more]


def eigen_interface(prefix: str, dims: dict, docs: dict) -> dict:
    """types: the EigenTypes (joint and parameter vectors first); largest: the biggest of them;
    wrappers: one per catalogue function. dims: dimension name -> size (catalogue.dimensions);
    docs: C name -> the function's documentation (as in the C header)."""
    types: dict[str, EigenType] = {}

    def use(name, shape):
        rows, cols = (dims[shape[0]], 1) if len(shape) == 1 else (dims[shape[0]], dims[shape[1]])
        known = types.setdefault(name, EigenType(name, rows, cols))
        assert (known.rows, known.cols) == (rows, cols), (name, known, rows, cols)
        return name

    wrappers = []
    has_gravity = dims["gravity_symbols"] > 0
    for f in FUNCTIONS:
        c_name = f"{prefix}_{f.name}"
        inputs = [(arg, use(ARGUMENTS[arg].eigen, ARGUMENTS[arg].shape)) for arg in f.arguments(has_gravity)]
        output, *more = [(o.name, use(o.eigen, o.shape)) for o in f.outputs]
        wrappers.append(Wrapper(f.name, c_name, docs.get(c_name, f.doc), inputs, output, more))
    first = ["Joints", "Parameters", "GravitySymbols", "MassMatrix"]
    ordered = sorted(types.values(), key=lambda t: first.index(t.name) if t.name in first else len(first))
    largest = max(ordered, key=lambda t: t.rows * t.cols)
    return {"types": ordered, "largest": largest, "wrappers": wrappers}
