"""C99 text of one straight-line program: per-link sections, no heap, only <math.h>.

Inputs are flat arrays (q[0] is joint 1), constants go through the robot's cast macro
(<P>_K(0.39)) so that a float build computes in float, and x**2 is written x*x.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp
from sympy.printing.c import C99CodePrinter

from ..derivation.program import Assignment
from .factoring import factored
from .opcount import OpCount, count_all
from .schedule import NOT_SUNK, scheduled
from .shared import shared_products


@dataclass
class CFunction:
    name: str
    doc: str
    inputs: list  # (argument name, length, meaning)
    output: tuple  # (argument name, shape, meaning)
    body: list[str]
    ops: OpCount
    used: set  # input arguments the body reads (the others are cast to void)
    more: list = field(default_factory=list)  # further outputs (argument name, shape, meaning), after output

    @property
    def outputs(self) -> list:
        return [self.output, *self.more]


class Printer(C99CodePrinter):
    def __init__(self, prefix: str, names: dict):
        super().__init__({"strict": False})
        self.macro = prefix.upper()
        self.names = names  # symbol -> C text (array entries)

    def _print_Symbol(self, expr):
        return self.names.get(expr, expr.name)

    def _print_Rational(self, expr):
        text = decimal_text(expr)
        if len(text) > 24:  # a folded-in parameter product (rnea_nominal): the nearest double
            text = repr(float(expr))
        return f"{self.macro}_K({text})"

    def _print_Integer(self, expr):
        return str(int(expr))

    def _print_Float(self, expr):
        return f"{self.macro}_K({float(expr)!r})"

    def _print_Mul(self, expr):
        coeff, rest = expr.as_coeff_Mul()
        constant, rest = _constant_part(expr)
        if not constant.is_Rational:  # sqrt(2)/2*x: one constant, as opcount.py counts it
            sign = "-" if constant < 0 else ""
            return f"{sign}{self._print_irrational(abs(constant))}*{self.parenthesize(rest, 50)}"
        if coeff.is_Rational and not coeff.is_Integer:
            sign = "-" if coeff < 0 else ""
            return f"{sign}{self._print_Rational(abs(coeff))}*{self.parenthesize(rest, 50)}"
        return super()._print_Mul(expr)

    def _print_irrational(self, expr):
        """An exact constant like sqrt(2)/2 (a twist of pi/4), as the double nearest to it."""
        return f"{self.macro}_K({float(expr)!r})"

    def _print_Pow(self, expr):
        if expr.is_number:
            return self._print_irrational(expr)
        if expr.exp.is_Integer and 1 < expr.exp <= 4:
            base = self.parenthesize(expr.base, 100)
            return "*".join([base] * int(expr.exp))
        if expr.exp == -1:
            return f"{self.macro}_K(1)/{self.parenthesize(expr.base, 100)}"
        return super()._print_Pow(expr)

    def _print_sin(self, expr):
        return f"{self.macro}_SIN({self._print(expr.args[0])})"

    def _print_cos(self, expr):
        return f"{self.macro}_COS({self._print(expr.args[0])})"


def _constant_part(expr):
    """(numeric factor, the rest) of a product: sqrt(2)/2*x -> (sqrt(2)/2, x)."""
    numbers = [f for f in expr.args if f.is_number]
    return sp.Mul(*numbers), sp.Mul(*(f for f in expr.args if not f.is_number))


def decimal_text(r: sp.Rational) -> str:
    """39/100 -> 0.39 when the decimal terminates; otherwise a quotient the compiler folds."""
    p, q = int(r.p), int(r.q)
    twos = fives = 0
    while q % 2 == 0:
        q //= 2; twos += 1
    while q % 5 == 0:
        q //= 5; fives += 1
    if q == 1:
        digits = max(twos, fives)
        text = f"{abs(p) * 10**digits // int(r.q):d}"
        text = text.rjust(digits + 1, "0")
        text = (text[:-digits] + "." + text[-digits:]).rstrip("0").rstrip(".") if digits else text + ".0"
        return ("-" if p < 0 else "") + text
    return f"{p}.0/{int(r.q)}.0"


def input_names(model) -> dict:
    return {sym: f"{inp.name}[{k}]" for inp in model.inputs for k, sym in enumerate(inp.symbols)}


@dataclass
class StraightLine:
    """The C statements of a program's assignments that some outputs need."""

    body: list[str]  # the joint angles' sin/cos, then per-section const declarations
    printer: Printer  # prints expressions over the declared names and the inputs
    ops: OpCount  # of the statements in body
    used: set  # input arguments the statements or outputs read


def straight_line(prefix: str, joint_models, model, outputs) -> StraightLine:
    """Declarations of everything `outputs` (expressions of the model's program) need."""
    outputs_free = set().union(*(sp.sympify(o).free_symbols for o in outputs))
    written = [Assignment(a.symbol, factored(a.expr), a.section) for a in model.program.pruned(outputs)]
    pruned = scheduled(shared_products(written, outputs_free), outputs_free, model.trig,
                       sink=getattr(model, "name", None) not in NOT_SUNK)
    names = input_names(model)
    names.update({a.symbol: f"x{k}" for k, a in enumerate(pruned)})  # dense numbering: stable diffs
    printer = Printer(prefix, names)
    real = f"{prefix}_real"
    body = []
    trig_used = sorted({s for a in pruned for s in a.expr.free_symbols if s in model.trig} |
                       {s for o in outputs for s in sp.sympify(o).free_symbols if s in model.trig},
                       key=lambda s: (model.trig[s][0], model.trig[s][1]))
    per_joint = {}
    for s in trig_used:
        joint, fn = model.trig[s]
        per_joint.setdefault(joint, {})[fn] = s
    angles = {joint: _angle_lines(prefix, joint_models, joint, fns) for joint, fns in per_joint.items()}
    # each angle's sine and cosine just before their first use: fewer values live at once (the
    # C compiler keeps the order; twelve sines and cosines held from the top spill to the stack)
    first_use = {}
    for k, a in enumerate(pruned):
        for s in a.expr.free_symbols & set(trig_used):
            first_use.setdefault(model.trig[s][0], k)
    seen = set()
    written = [a.expr for a in pruned]
    for k, (a, expr) in enumerate(zip(pruned, written)):
        if a.section not in seen:  # statements are scheduled (schedule.py): a section's comment marks its start
            seen.add(a.section)
            body.append(f"/* {a.section} */")
        for joint in sorted(j for j, first in first_use.items() if first == k):
            body += angles[joint]
        body.append(f"const {real} {names[a.symbol]} = {printer.doprint(expr)};")
    late = [j for j in angles if j not in first_use]  # read only by the outputs
    if late:
        body.append("/* joint angles */")
        for joint in sorted(late):
            body += angles[joint]
    ops = count_all(written) + OpCount(trig=len(per_joint))  # a sin/cos pair counts once
    free = set().union(*(a.expr.free_symbols for a in pruned), *(sp.sympify(o).free_symbols for o in outputs))
    used = {inp.name for inp in model.inputs if free & set(inp.symbols)}
    if trig_used:
        used.add("q")
    return StraightLine(body, printer, ops, used)


def _angle_lines(prefix: str, joint_models, joint: int, fns: dict) -> list[str]:
    """The C that defines one joint angle's sine and/or cosine (one sincos for both)."""
    real, macro = f"{prefix}_real", prefix.upper()
    angle = f"q[{joint}]"
    offset = joint_models[joint].offset
    if offset != 0:
        angle = f"q[{joint}] + {macro}_K({float(offset)!r})"
    if len(fns) == 2:
        return [f"{real} {fns['sin'].name}, {fns['cos'].name};",
                f"{macro}_SINCOS({angle}, &{fns['sin'].name}, &{fns['cos'].name});"]
    return [f"const {real} {s.name} = {macro}_{fn.upper()}({angle});" for fn, s in fns.items()]


def render_function(prefix: str, joint_models, name: str, model, outputs, output, doc: str) -> CFunction:
    """outputs: flat expressions written to output[0] (argument name, shape, meaning)."""
    code = straight_line(prefix, joint_models, model, outputs)
    body = code.body + [f"/* {output[0]} */"]
    flat = [sp.sympify(o) for o in outputs]
    zeros = sum(1 for o in flat if o == 0)
    if zeros > 8:
        body.append(f"for (int k = 0; k < {len(flat)}; ++k) {output[0]}[k] = 0;")
    for k, o in enumerate(flat):
        if o != 0 or zeros <= 8:
            body.append(f"{output[0]}[{k}] = {code.printer.doprint(o)};")
    ins = [(inp.name, len(inp.symbols), inp.doc) for inp in model.inputs]
    return CFunction(f"{prefix}_{name}", doc, ins, output, body, code.ops + count_all(flat), code.used)
