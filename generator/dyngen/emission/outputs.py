"""C of one straight-line program that writes several output arrays (control()): the
program's flat outputs are the arrays' entries one after the other."""

from __future__ import annotations

import math

import sympy as sp

from .c_code import CFunction, straight_line
from .opcount import count_all


def render_outputs(prefix: str, joint_models, name: str, model, outputs: list, doc: str) -> CFunction:
    """outputs: (argument name, shape, meaning) per array, in the order of model.outputs."""
    code = straight_line(prefix, joint_models, model, model.outputs)
    flat = [sp.sympify(o) for o in model.outputs]
    assert len(flat) == sum(math.prod(shape) for _, shape, _ in outputs), (name, len(flat))
    body, start = list(code.body), 0
    for arg, shape, _ in outputs:
        body.append(f"/* {arg} */")
        for k in range(math.prod(shape)):
            body.append(f"{arg}[{k}] = {code.printer.doprint(flat[start + k])};")
        start += math.prod(shape)
    ins = [(inp.name, len(inp.symbols), inp.doc) for inp in model.inputs]
    return CFunction(f"{prefix}_{name}", doc, ins, outputs[0], body, code.ops + count_all(flat), code.used,
                     more=list(outputs[1:]))
