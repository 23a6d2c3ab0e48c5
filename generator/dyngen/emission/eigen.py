"""The Eigen types of the generated functions' arguments, for the C++ header <robot>.hpp.

Every flat C array gets a fixed-size Eigen type with the same memory layout, so a wrapper
can hand the caller's storage to the C function unchanged: vectors are column vectors,
matrices row-major (the C layout).
"""

from __future__ import annotations

from dataclasses import dataclass

INPUT_TYPES = {"q": "Joints", "qd": "Joints", "qdd": "Joints", "p": "Parameters", "s": "Parameters",
               "gravity": "GravitySymbols"}
OUTPUT_TYPES = {"tau": "Joints", "g": "Joints", "s": "Parameters"}  # otherwise named after the function
TYPE_DOCS = {
    "Joints": "one entry per joint: q, qd, qdd, tau, g",
    "Parameters": "10 per link, link 1 first: p (dynamic) or s (standard)",
    "GravitySymbols": "values of the gravity symbols, in the header's order",
    "MassMatrix": "M(q), symmetric",
    "RegressorGravity": "Y_g(q): g = Y_g pi_gravity",
    "RegressorInertia": "Y_m(q): row k is entry k of the stacked upper triangle of M (M11, M12, ..., MNN)",
    "Regressor": "Y(q, qd, qdd): tau = Y pi_full",
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


def camel(name: str) -> str:
    return "".join(part.capitalize() for part in name.split("_"))


def eigen_interface(prefix: str, functions) -> dict:
    """types: the EigenTypes (joint and parameter vectors first); largest: the biggest of them;
    wrappers: one per C function."""
    types: dict[str, EigenType] = {}

    def use(name, rows, cols):
        known = types.setdefault(name, EigenType(name, rows, cols))
        assert (known.rows, known.cols) == (rows, cols), (name, known, rows, cols)
        return name

    wrappers = []
    for f in functions:
        short = f.name[len(prefix) + 1:]
        inputs = [(arg, use(INPUT_TYPES[arg], length, 1)) for arg, length, _ in f.inputs]
        out_arg, shape, _ = f.output
        rows, cols = (shape[0], 1) if len(shape) == 1 else shape
        out_type = OUTPUT_TYPES.get(out_arg, camel(short))
        wrappers.append(Wrapper(short, f.name, f.doc, inputs, (out_arg, use(out_type, rows, cols))))
    first = ["Joints", "Parameters", "GravitySymbols", "MassMatrix"]
    ordered = sorted(types.values(), key=lambda t: first.index(t.name) if t.name in first else len(first))
    largest = max(ordered, key=lambda t: t.rows * t.cols)
    return {"types": ordered, "largest": largest, "wrappers": wrappers}
