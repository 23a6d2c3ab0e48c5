"""Each product formed once per emitted function: a product that two statements (or one twice)
write is given its own statement, and both read it.

Program.let shares identical expressions, not identical parts of different ones: the composite
bodies turn h by one joint angle in the body's moment and again in the wrench carried down
(s66 c7 - s68 s7 and s56 + s66 c7 - s68 s7), the standard parameters square a centre of mass
coordinate in each of two inertia entries (m cx^2 in YY and ZZ), the factoring leaves
0.5 (a + b) in J00 and in J11. gcc -O2 would merge some of them (identical operands in one basic
block) but not the count, and a merge it cannot see (a product inside a longer one) costs an
instruction. A product is a multiplication node of the factored statement (emission/factoring.py)
with its factors as a set and its numeric coefficient by size: -2 a b and 2 b a are one product,
read with its sign. The outermost repeated products go first, so a repeated product inside
another one that is repeated whole is not split out; the loop ends when none repeats.
"""

from __future__ import annotations

from collections import Counter

import sympy as sp

from ..derivation.program import Assignment


def shared_products(assignments: list, outputs_free: set) -> list:
    """assignments (expressions as written, factored) with every repeated product its own
    assignment, placed before the first statement that reads it; then the statements left
    copying or negating one value (x12 = x10, x20 = -x18: a product that was a whole statement)
    are read through in their readers, unless an output reads them."""
    return _read_through(_products_once(assignments), outputs_free)


def _read_through(assignments: list, outputs_free: set) -> list:
    """A copy x = y or negation x = -y is a move or a sign flip (xorpd) that the reader can do
    for free: a - (-y) is a + y, and a sign in a product joins its coefficient."""
    through, kept = {}, []
    for a in assignments:
        expr = _replaced(a.expr, lambda node: through.get(node) if node.is_Symbol else None)
        single = expr.is_Symbol or (expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1
                                    and expr.args[1].is_Symbol)
        if single and a.symbol not in outputs_free:
            through[a.symbol] = expr
        else:
            kept.append(Assignment(a.symbol, expr, a.section))
    return kept


def _products_once(assignments: list) -> list:
    """Rounds until no product repeats: each round names the outermost repeated products
    (shared0, shared1, ... in the order of first use) and rewrites the statements to read them."""
    made = 0
    while True:
        counts = Counter()
        for a in assignments:
            _collect(a.expr, counts)
        repeated = {k for k, n in counts.items() if n > 1}
        if not repeated:
            _KEYS.clear()
            return assignments
        outermost = _outermost(assignments, repeated)
        names, placed = {}, []
        for a in assignments:  # numbered in the order of first use: deterministic output
            needed = []
            _keys_in(a.expr, outermost, needed)
            for key in needed:
                if key not in names:
                    names[key] = sp.Symbol(f"shared{made}", real=True)
                    made += 1
                    placed.append(Assignment(names[key], _product(key), a.section))
            placed.append(Assignment(a.symbol, _replaced(a.expr, lambda node: _named(node, names)), a.section))
        assignments = placed


_KEYS: dict = {}


def _key(node):
    """Memoised _product_key (sympy nodes hash once; the loop revisits every node)."""
    found = _KEYS.get(node)
    if found is None:
        found = _KEYS[node] = _product_key(node)
    return found


def _product_key(node):
    """(size of the numeric coefficient, sorted other factors), sign; None if no product."""
    if node.is_Pow and node.exp.is_Integer and 1 < node.exp <= 4 and not node.base.is_number:
        return (sp.Integer(1), (node,)), 1
    if not node.is_Mul or node.is_number:  # sqrt(2)/20 is a constant the printer writes as one literal
        return None, 1
    numbers = sp.Mul(*(f for f in node.args if f.is_Number))
    signed = [_signed_factor(f) for f in node.args if not f.is_Number]
    others = tuple(sorted((f for f, _ in signed), key=sp.default_sort_key))
    if len(others) + (abs(numbers) != 1) < 2:
        return None, 1
    sign = (-1 if numbers < 0 else 1) * sp.prod(s for _, s in signed)
    return (abs(numbers), others), sign


def _signed_factor(f):
    """(f or -f, sign): a sum and its negation are one factor (c (a - b) and c (b - a))."""
    if not f.is_Add:
        return f, 1
    negated = sp.Add(*(_negated(a) for a in f.args), evaluate=False)
    return (f, 1) if sp.default_sort_key(f) <= sp.default_sort_key(negated) else (negated, -1)


def _negated(term):
    """-term without re-evaluating it (a number times a sum would be multiplied out)."""
    if term.is_Symbol:
        return -term
    if term.is_Mul and term.args[0].is_Number:
        c, rest = -term.args[0], list(term.args[1:])
        return rest[0] if c == 1 and len(rest) == 1 else sp.Mul(*([c] if c != 1 else []), *rest, evaluate=False)
    return sp.Mul(-1, term, evaluate=False)


def _product(key):
    size, others = key
    if size == 1 and len(others) == 1 and others[0].is_Pow:  # x**2; with a size (c sqrt(2) x) it is a Mul
        return others[0]
    return sp.Mul(*(([size] if size != 1 else []) + list(others)), evaluate=False)


def _rest_key(node):
    """The product inside c x y (|c| != 1): the printer writes c*(x*y), so x*y is formed first."""
    if not node.is_Mul:
        return None
    numbers = [f for f in node.args if f.is_Number]
    others = tuple(sorted((f for f in node.args if not f.is_Number), key=sp.default_sort_key))
    if not numbers or abs(sp.Mul(*numbers)) == 1 or len(others) < 2:
        return None
    return sp.Integer(1), others


def _collect(node, counts):
    key, _ = _key(node)
    if key is not None:
        counts[key] += 1
    rest = _rest_key(node)
    if rest is not None:
        counts[rest] += 1
    for arg in node.args:
        if not arg.is_Atom:
            _collect(arg, counts)


def _outermost(assignments, repeated) -> set:
    """The repeated products that no other repeated product contains."""
    inner = set()

    def visit(node, inside):
        key, _ = _key(node)
        here = key in repeated
        if here and inside:
            inner.add(key)
        rest = _rest_key(node)
        if rest in repeated and (inside or here):
            inner.add(rest)
        for arg in node.args:
            if not arg.is_Atom:
                visit(arg, inside or here)

    for a in assignments:
        visit(a.expr, False)
    return repeated - inner


def _keys_in(node, names, found):
    """The keys of `names` that node holds, outermost first, each once."""
    key, _ = _key(node)
    if key in names:
        if key not in found:
            found.append(key)
        return
    rest = _rest_key(node)
    if rest in names and rest not in found:
        found.append(rest)
    for arg in node.args:
        if not arg.is_Atom:
            _keys_in(arg, names, found)


def _named(node, names):
    """The shared symbol standing for node (with node's sign), or None."""
    key, sign = _key(node)
    if key in names:
        return names[key] if sign > 0 else sp.Mul(-1, names[key], evaluate=False)
    rest = _rest_key(node)
    if rest in names:  # c x y -> c t
        return sp.Mul(sp.Mul(*(f for f in node.args if f.is_Number)), names[rest], evaluate=False)
    return None


def _replaced(node, lookup):
    """node with each part for which lookup gives an expression replaced by it, outermost first."""
    found = lookup(node)
    if found is not None:
        return found
    if node.is_Atom:
        return node
    args = [_replaced(a, lookup) for a in node.args]
    if node.is_Mul:  # a factor turned -t: its sign joins the product's coefficient
        sign, flat = 1, []
        for a in args:
            if a.is_Mul and len(a.args) == 2 and a.args[0] == -1:
                sign, a = -sign, a.args[1]
            flat.append(a)
        numbers = sp.Mul(sign, *(f for f in flat if f.is_Number))
        rest = [f for f in flat if not f.is_Number]
        return sp.Mul(*([numbers] if numbers != 1 else []), *rest, evaluate=False)
    return node.func(*args, evaluate=False)
