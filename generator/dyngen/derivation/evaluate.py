"""Numeric value of a Model at given inputs, straight from its SymPy program (no C involved).

The generator's own numeric check: the values embedded in the generated self-test come
from here. Arithmetic is 40-digit mpmath, so the results (rounded to double once, at the
end) do not depend on summation order and are the same on every machine.
"""

from __future__ import annotations

import mpmath
import sympy as sp

DIGITS = 40


def evaluate(model, joint_models, inputs: dict) -> list[float]:
    """model: a derivation Model; joint_models: the robot's (for the angle offsets);
    inputs: argument name -> flat list of numbers. Returns the flat outputs as floats."""
    with mpmath.workdps(DIGITS):
        env = {}
        for inp in model.inputs:
            values = inputs[inp.name]
            if len(values) != len(inp.symbols):
                raise ValueError(f"{model.name}: {inp.name} needs {len(inp.symbols)} values, got {len(values)}")
            env.update({sym: mpmath.mpf(v) for sym, v in zip(inp.symbols, values)})
        for sym, (joint, fn) in model.trig.items():  # sin/cos of q + offset, as the emitted C computes them
            angle = mpmath.mpf(inputs["q"][joint]) + _value(sp.sympify(joint_models[joint].offset), env)
            env[sym] = mpmath.sin(angle) if fn == "sin" else mpmath.cos(angle)
        for a in model.assignments:
            env[a.symbol] = _value(a.expr, env)
        return [float(_value(sp.sympify(o), env)) for o in model.outputs]


def _value(expr, env):
    if expr.is_Symbol:
        return env[expr]
    if expr.is_Rational:
        return mpmath.mpf(int(expr.p)) / int(expr.q)
    if expr.is_Float:
        return mpmath.mpf(expr._mpf_)
    if expr.is_number and not expr.args:  # pi, E
        return mpmath.mpf(sp.N(expr, DIGITS + 5)._mpf_)
    if expr.is_Add:
        return mpmath.fsum(_value(a, env) for a in expr.args)
    if expr.is_Mul:
        return mpmath.fprod(_value(a, env) for a in expr.args)
    if expr.is_Pow:
        return _value(expr.base, env) ** _value(expr.exp, env)
    if isinstance(expr, sp.sin):
        return mpmath.sin(_value(expr.args[0], env))
    if isinstance(expr, sp.cos):
        return mpmath.cos(_value(expr.args[0], env))
    raise TypeError(f"cannot evaluate {type(expr).__name__}: {expr}")
