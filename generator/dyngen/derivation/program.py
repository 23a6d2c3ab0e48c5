"""Straight-line code collected while a recursion is built (the SymPyBotics idea).

Every non-trivial expression handed to `Program.let` becomes a fresh variable x<k>
(or reuses the variable of an identical expression seen before), so expressions never
swell: each stays a small polynomial in earlier variables. Assignments remember the
section they were made in ("link 3: forward") so emitted code reads per link.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp


@dataclass
class Assignment:
    symbol: sp.Symbol
    expr: sp.Expr
    section: str


@dataclass
class Program:
    prefix: str = "x"
    assignments: list[Assignment] = field(default_factory=list)
    section: str = ""
    _known: dict = field(default_factory=dict)

    def let(self, expr) -> sp.Expr:
        """A variable holding expr, or expr itself when it is trivial (a number, a symbol, -symbol)."""
        expr = sp.sympify(expr)
        if _trivial(expr):
            return expr
        if expr in self._known:
            return self._known[expr]
        if -expr in self._known:
            return -self._known[-expr]
        symbol = sp.Symbol(f"{self.prefix}{len(self.assignments)}", real=True)
        self.assignments.append(Assignment(symbol, expr, self.section))
        self._known[expr] = symbol
        return symbol

    def let_vector(self, exprs) -> list[sp.Expr]:
        return [self.let(e) for e in exprs]

    def pruned(self, outputs) -> list[Assignment]:
        """The assignments the outputs need, in order (dead code dropped)."""
        needed = set()
        for expr in outputs:
            needed |= sp.sympify(expr).free_symbols
        kept = []
        for a in reversed(self.assignments):
            if a.symbol in needed:
                kept.append(a)
                needed |= a.expr.free_symbols
        return kept[::-1]


def _trivial(expr: sp.Expr) -> bool:
    if expr.is_Atom:
        return True
    return expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1 and expr.args[1].is_Atom


# ---- small vector algebra on lists of three expressions -------------------------------

def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def add(*vectors):
    return [sp.Add(*components) for components in zip(*vectors)]


def scale(k, v):
    return [k * x for x in v]


def mat_vec(matrix: sp.Matrix, v):
    return [sp.Add(*(matrix[r, c] * v[c] for c in range(3))) for r in range(3)]


def mat_t_vec(matrix: sp.Matrix, v):
    return [sp.Add(*(matrix[c, r] * v[c] for c in range(3))) for r in range(3)]
