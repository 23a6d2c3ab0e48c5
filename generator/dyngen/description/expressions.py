"""Exact expressions from untrusted text: 0.39 -> 39/100, "pi/2" -> pi/2, "c7y*m7" -> c7y*m7.

Every expression a user writes (DH entries, gravity, identified coefficients, identities)
goes through this one parser. It walks Python's ast and accepts only numbers, `pi`, names
the caller allows, + - * / **, unary signs and parentheses: nothing is called, no attribute
is read, nothing is exec'd or sympify'd. Because the text may come from anyone, the size of
the work is bounded before and during evaluation: the length of the text, the number and
depth of its nodes, exponents (small integer literals), the size of exact numbers and the
polynomial degree. A limit that is hit is named in the error.
"""

from __future__ import annotations

import ast
import math
import re
import unicodedata
from typing import Callable, Mapping

import sympy as sp

from ..errors import shorten

MAX_CHARACTERS = 2000  # one expression (a 20-link coefficient needs a few hundred)
MAX_NODES = 600
MAX_DEPTH = 40
MAX_EXPONENT = 8  # x**k with a literal integer |k| <= 8
MAX_BITS = 256  # numerator and denominator of any exact number met on the way
MAX_DEGREE = 6  # polynomial degree in the named symbols (identities need 3)

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,31}")


class ExpressionError(ValueError):
    pass


# The characters an expression may hold. Python's parser would take more, and silently: it
# NFKC-normalises identifiers (a fullwidth "ｍ２" is m2, a superscript "m²" is m2 too) and reads
# "π" as a name. So the text is first rewritten here, one character at a time, to plain ASCII:
# what a person plainly means is translated (the lookalikes below; any space, such as a
# non-breaking one; fullwidth ASCII), everything else outside printable ASCII is refused with
# its column. Nothing reaches ast.parse that is not ASCII.
_ASCII = re.compile(r"[A-Za-z0-9_ .+\-*/()]", re.ASCII)
_MEANT = {
    "\u2212": "-",  # MINUS SIGN
    "\u2215": "/",  # DIVISION SLASH
    "\u00f7": "/",  # DIVISION SIGN
    "\u00d7": "*",  # MULTIPLICATION SIGN
    "\u22c5": "*",  # DOT OPERATOR
    "\u00b7": "*",  # MIDDLE DOT
    "\u2217": "*",  # ASTERISK OPERATOR
    "\u03c0": "pi",  # GREEK SMALL LETTER PI
}


def _plain(text: str) -> str:
    """`text` in the ASCII the parser reads, or ExpressionError naming the first column that is
    neither ASCII dyngen reads nor a character it translates."""
    out = []
    for column, char in enumerate(text, start=1):
        if "\uff01" <= char <= "\uff5e":  # fullwidth ASCII, as an East Asian keyboard types it
            char = chr(ord(char) - 0xFEE0)
        if _ASCII.fullmatch(char):
            out.append(char)
        elif char in _MEANT:
            out.append(_MEANT[char])
        elif char == "\t" or unicodedata.category(char) == "Zs":  # tab, no-break space, thin space, ...
            out.append(" ")
        else:
            what = f"U+{ord(char):04X} {unicodedata.name(char, 'unnamed character')}"
            raise ExpressionError(f'got "{shorten(text)}" (column {column}: {what} is not part of an '
                                  "expression; numbers, names, pi and + - * / ** ( ) only)")
    return "".join(out)


def exact_number(value, allow_symbols: bool = False, reserved: Callable[[str], bool] | None = None) -> sp.Expr:
    """A YAML scalar (number or expression of pi) as an exact SymPy number; with allow_symbols,
    names other than pi become real symbols unless `reserved(name)`. Raises ExpressionError."""
    if isinstance(value, bool) or value is None:
        raise ExpressionError(f"got {value!r}")
    if isinstance(value, int):
        return _checked(sp.Integer(value), str(value))
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ExpressionError(f"got {value!r} (not a finite number)")
        return _checked(sp.Rational(repr(value)), repr(value))
    if isinstance(value, str):
        def symbol(name):
            if not allow_symbols:
                return None
            if not _IDENTIFIER.fullmatch(name) or (reserved and reserved(name)):
                raise ExpressionError(f'got "{shorten(value)}": the name {shorten(name)} is reserved or not a '
                                      "symbol name (letters, digits, _; at most 32 characters)")
            return sp.Symbol(name, real=True)

        return parse(value, symbol)
    raise ExpressionError(f"got {type(value).__name__}")


def parse_expression(text: str, names: Mapping[str, sp.Symbol]) -> sp.Expr:
    """An expression over the given names (e.g. parameter names); any other name is refused."""
    return parse(text, names.get)


def parse(text: str, symbol: Callable[[str], sp.Expr | None]) -> sp.Expr:
    """The whitelisted walk. `symbol(name)` gives a name's value, or None when it is unknown."""
    if not isinstance(text, str):
        raise ExpressionError(f"expected text, got {type(text).__name__}")
    if len(text) > MAX_CHARACTERS:
        raise ExpressionError(f"got {len(text)} characters (at most {MAX_CHARACTERS} in one expression)")
    plain = _plain(text)
    try:
        tree = ast.parse(plain.strip(), mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        raise ExpressionError(f'got "{shorten(text)}" (not an arithmetic expression)') from None
    _check_size(tree.body, text)
    try:
        value, _ = _Walker(symbol, text).value(tree.body)
    except RecursionError:
        raise ExpressionError(f'got "{shorten(text)}" (nested too deeply)') from None
    return value


def _check_size(root, text):
    """Node count and depth, without recursion (the walk below recurses only within these bounds)."""
    count, stack = 0, [(root, 1)]
    while stack:
        node, depth = stack.pop()
        count += 1
        if count > MAX_NODES:
            raise ExpressionError(f'got "{shorten(text)}" (more than {MAX_NODES} terms and operators)')
        if depth > MAX_DEPTH:
            raise ExpressionError(f'got "{shorten(text)}" (nested more than {MAX_DEPTH} deep)')
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))


def _checked(number: sp.Expr, text: str) -> sp.Expr:
    """Refuse exact numbers too large or too fine to be a robot's constant, and anything not finite."""
    if number.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise ExpressionError(f'got "{shorten(text)}" (not a finite number)')
    for atom in number.atoms(sp.Rational):
        if max(int(atom.p).bit_length(), int(atom.q).bit_length()) > MAX_BITS:
            raise ExpressionError(f'got "{shorten(text)}" (value out of range)')
    return number


class _Walker:
    """Evaluates the checked tree; each value comes with its polynomial degree in the symbols."""

    def __init__(self, symbol, text):
        self.symbol, self.text = symbol, text

    def fail(self, why):
        raise ExpressionError(f'got "{shorten(self.text)}" ({why})')

    def value(self, node) -> tuple[sp.Expr, int]:
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                self.fail("only numbers, names and + - * / ** are allowed")
            if isinstance(node.value, float):
                if not math.isfinite(node.value):
                    self.fail("value out of range")
                return _checked(sp.Rational(repr(node.value)), self.text), 0
            if node.value.bit_length() > MAX_BITS:
                self.fail("value out of range")
            return sp.Integer(node.value), 0
        if isinstance(node, ast.Name):
            if node.id == "pi":
                return sp.pi, 0
            found = self.symbol(node.id)
            if found is None:
                self.fail(f"unknown name {shorten(node.id)}")
            return found, 1
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            inner, degree = self.value(node.operand)
            return (-inner if isinstance(node.op, ast.USub) else inner), degree
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            return self.power(node)
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult, ast.Div)):
            (a, da), (b, db) = self.value(node.left), self.value(node.right)
            if isinstance(node.op, ast.Add):
                return self.result(a + b, max(da, db))
            if isinstance(node.op, ast.Sub):
                return self.result(a - b, max(da, db))
            if isinstance(node.op, ast.Mult):
                return self.result(a * b, da + db)
            if db:
                self.fail("division by a parameter is not allowed")
            if b == 0:
                self.fail("division by zero")
            return self.result(a / b, da)
        self.fail("only numbers, names and + - * / ** are allowed")

    def power(self, node):
        exponent = node.right
        sign = 1
        if isinstance(exponent, ast.UnaryOp) and isinstance(exponent.op, (ast.USub, ast.UAdd)):
            sign = -1 if isinstance(exponent.op, ast.USub) else 1
            exponent = exponent.operand
        if not (isinstance(exponent, ast.Constant) and type(exponent.value) is int
                and abs(exponent.value) <= MAX_EXPONENT):
            self.fail(f"exponents must be whole numbers from -{MAX_EXPONENT} to {MAX_EXPONENT}")
        k = sign * exponent.value
        base, degree = self.value(node.left)
        if k < 0 and degree:
            self.fail("negative powers of a parameter are not allowed")
        if k < 0 and base == 0:
            self.fail("division by zero")
        return self.result(base ** k, degree * abs(k))

    def result(self, value, degree):
        if degree > MAX_DEGREE:
            self.fail(f"polynomial degree above {MAX_DEGREE}")
        return _checked(value, self.text), degree
