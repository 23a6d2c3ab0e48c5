"""Exact evaluation of straight-line code over the prime field GF(P).

The regressors are polynomials in sin/cos of the joint angles (and in q for prismatic
joints, qd, qdd and gravity symbols) with rational coefficients. At the rational points
(cos, sin) = ((1 - t^2)/(1 + t^2), 2t/(1 + t^2)) of the unit circle they take rational
values; evaluated modulo a large prime they give, with probability ~1 - 1e-30, the exact
rank over the rationals. No floating point tolerance is involved.
"""

from __future__ import annotations

import bisect
import random
from contextlib import contextmanager

import sympy as sp

# Mersenne primes, smallest first. Rational reconstruction recovers a/b with |a|, b below
# sqrt(P/2): 63 bits for the first, which every arm of up to about 25 joints needs; longer
# chains regroup with coefficients of 100 bits and more (a 30-joint arm: 111), so the reduction
# is redone with the next prime when the first cannot hold them (reduction/base.py).
PRIMES = ((1 << 127) - 1, (1 << 521) - 1, (1 << 1279) - 1)
P = PRIMES[0]  # the field in use; switched only by prime_field below


class Reconstruction(ArithmeticError):
    """The field is too small for the exact rationals: try the next prime."""


@contextmanager
def prime_field(prime: int):
    """Compute in GF(prime) inside the block (every function here reads P when called)."""
    global P
    previous, P = P, prime
    try:
        yield
    finally:
        P = previous


def inverse(x: int) -> int:
    return pow(x % P, P - 2, P)


def to_field(value) -> int:
    r = sp.Rational(value)
    return (int(r.p) * inverse(int(r.q))) % P


def circle_point(rng: random.Random) -> tuple[int, int]:
    """(cos, sin) of a random rational angle, in GF(P)."""
    t = rng.randrange(1, P)
    den = inverse(1 + t * t)
    return ((1 - t * t) * den) % P, (2 * t * den) % P


def evaluate(expr, env: dict, cache: dict) -> int:
    """expr in GF(P); env maps symbols to field values; cache memoises numbers."""
    if expr.is_Symbol:
        return env[expr]
    if expr.is_Number:
        if expr not in cache:
            cache[expr] = to_field(expr)
        return cache[expr]
    if expr.is_Add:
        total = 0
        for arg in expr.args:
            total += evaluate(arg, env, cache)
        return total % P
    if expr.is_Mul:
        product = 1
        for arg in expr.args:
            product = (product * evaluate(arg, env, cache)) % P
        return product
    if expr.is_Pow and expr.exp.is_Integer:
        base = evaluate(expr.base, env, cache)
        e = int(expr.exp)
        return pow(base, e, P) if e >= 0 else pow(inverse(base), -e, P)
    raise ValueError(f"cannot evaluate {expr} exactly")


def run(assignments, outputs, env: dict) -> list[int]:
    """Evaluate a pruned program and its outputs at one point."""
    env = dict(env)
    cache: dict = {}
    for a in assignments:
        env[a.symbol] = evaluate(a.expr, env, cache)
    return [evaluate(sp.sympify(o), env, cache) for o in outputs]


def rational(x: int) -> sp.Rational:
    """Rational reconstruction: the a/b with |a|, b < sqrt(P/2) and a = b x mod P."""
    bound = 1 << ((P.bit_length() - 1) // 2)
    r0, r1, s0, s1 = P, x % P, 0, 1
    while r1 >= bound:
        quotient = r0 // r1
        r0, r1 = r1, r0 - quotient * r1
        s0, s1 = s1, s0 - quotient * s1
    if s1 == 0 or abs(s1) >= bound:
        raise Reconstruction("no small rational")
    return sp.Rational(r1, s1)


class Echelon:
    """A reduced row echelon basis over GF(P), grown one row at a time.

    Each basis row has a leading 1 in its pivot column and zeros in every other pivot
    column. A new row is reduced against the basis (dropped when nothing is left) and the
    basis against it: O(rank x columns) per row, so only the rows sampled are eliminated,
    not a tall matrix again and again. The result is the unique reduced form of the row space.
    """

    def __init__(self, n_cols: int):
        self.n_cols = n_cols
        self.pivots: list[int] = []  # increasing
        self.rows: list[list[int]] = []  # rows[r] belongs to pivots[r]

    def add(self, row) -> bool:
        """Adds row's new direction, if any; True when the rank grew."""
        row = [v % P for v in row]
        for pivot, basis in zip(self.pivots, self.rows):
            k = row[pivot]
            if k:  # a basis row is zero left of its pivot: only the columns from there on change
                row[pivot:] = [(v - k * w) % P for v, w in zip(row[pivot:], basis[pivot:])]
        col = next((c for c, v in enumerate(row) if v), None)
        if col is None:
            return False
        inv = inverse(row[col])
        row[col:] = [(v * inv) % P for v in row[col:]]
        for basis in self.rows:
            k = basis[col]
            if k:
                basis[col:] = [(v - k * w) % P for v, w in zip(basis[col:], row[col:])]
        at = bisect.bisect(self.pivots, col)
        self.pivots.insert(at, col)
        self.rows.insert(at, row)
        return True

