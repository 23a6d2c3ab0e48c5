"""Exact numbers from YAML values: 0.39 -> 39/100, "pi/2" -> pi/2, "g" -> Symbol g.

A tiny evaluator over Python's ast: numbers, pi, named symbols where allowed,
+ - * / ** and parentheses. Nothing is exec'd.
"""

from __future__ import annotations

import ast
import re

import sympy as sp

_OPS = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: lambda a, b: a ** b,
}
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class ExpressionError(ValueError):
    pass


def exact_number(value, allow_symbols: bool = False) -> sp.Expr:
    """A YAML scalar as an exact SymPy expression; raises ExpressionError."""
    if isinstance(value, bool) or value is None:
        raise ExpressionError(f"got {value!r}")
    if isinstance(value, int):
        return sp.Integer(value)
    if isinstance(value, float):
        if value != value or value in (float("inf"), float("-inf")):
            raise ExpressionError(f"got {value!r}")
        return sp.Rational(repr(value))
    if isinstance(value, str):
        try:
            tree = ast.parse(value.strip(), mode="eval")
            return _evaluate(tree.body, allow_symbols)
        except (SyntaxError, ExpressionError, ZeroDivisionError, TypeError):
            raise ExpressionError(f'got "{value}"') from None
    raise ExpressionError(f"got {type(value).__name__} {value!r}")


def _evaluate(node, allow_symbols):
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return exact_number(node.value)
    if isinstance(node, ast.Name):
        if node.id == "pi":
            return sp.pi
        if allow_symbols and _NAME.match(node.id):
            return sp.Symbol(node.id, real=True)
        raise ExpressionError(node.id)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = _evaluate(node.operand, allow_symbols)
        return -inner if isinstance(node.op, ast.USub) else inner
    if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
        return _OPS[type(node.op)](_evaluate(node.left, allow_symbols), _evaluate(node.right, allow_symbols))
    raise ExpressionError(ast.dump(node))
