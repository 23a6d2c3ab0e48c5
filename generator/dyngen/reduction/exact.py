"""Exact evaluation of straight-line code over a prime field GF(P).

The regressors are polynomials in sin/cos of the joint angles (and in q for prismatic
joints, qd, qdd and gravity symbols) whose coefficients are the arm's constants. At the
rational points (cos, sin) = ((1 - t^2)/(1 + t^2), 2t/(1 + t^2)) of the unit circle they
take values in the constants' field; evaluated modulo a large prime they give, with
probability ~1 - 1e-30, the exact rank. No floating point tolerance is involved.

The constants are rational (lengths, and cos/sin of a twist that is not a multiple of
pi/12: description/angles.py writes those as a rational point of the circle) or lie in
Q(sqrt 2, sqrt 3) (cos/sin of multiples of pi/12). A Field holds a prime and, when its
P = 1 mod 24, square roots of 2 and 3 in GF(P): one choice of their signs is one embedding
of Q(sqrt 2, sqrt 3) into GF(P) (reduction/base.py combines the embeddings). Rationals
with large numerators (a rational circle point has ~55-bit ones) need a larger prime for
their reconstruction, hence the FIELDS ladder.
"""

from __future__ import annotations

import bisect
import functools
import math
import random

import sympy as sp


class NotInField(ValueError):
    """A constant this field cannot hold, or a coefficient too large to reconstruct in it."""


class Field:
    """GF(P) holding the square roots in `roots` (base -> a root), under one choice of signs."""

    def __init__(self, P: int, bound: int, roots: dict | None = None, signs: dict | None = None):
        self.P, self.bound, self.roots = P, bound, roots or {}
        self.signs = signs or {b: 1 for b in self.roots}
        self._roots = {b: (self.signs[b] * r) % P for b, r in self.roots.items()}
        self.used: set = set()  # the roots some evaluation needed

    def embedding(self, signs: dict) -> "Field":
        """The same field with other signs for the roots (signs: base -> +-1)."""
        return Field(self.P, self.bound, self.roots, {**self.signs, **signs})

    def root(self, n: int) -> int:
        """sqrt(n) for a square-free n whose prime factors are roots of this field."""
        factors = sp.factorint(n)
        if any(e != 1 or f not in self._roots for f, e in factors.items()):
            raise NotInField(f"sqrt({n}) is not in this field")
        self.used.update(factors)
        return math.prod(self._roots[f] for f in factors) % self.P


MERSENNE = Field((1 << 127) - 1, 1 << 63)  # rational constants only (P = 3 mod 12: 3 has no root)
P = MERSENNE.P  # the default field's prime, for callers that need only it

# Primes P = 24 (2^bits // 24 + k) + 1 (P = 1 mod 24: 2 and 3 are squares mod P); each k found
# once with sympy.isprime (tests/test_general_frames.py checks them).
LADDER = ((256, 13), (640, 185), (1280, 107), (2560, 210), (4096, 74))


@functools.lru_cache(maxsize=None)
def ladder_field(bits: int, k: int) -> Field:
    prime = 24 * ((1 << bits) // 24 + k) + 1
    return Field(prime, math.isqrt(prime >> 1), {b: int(sp.sqrt_mod(b, prime)) for b in (2, 3)})


@functools.lru_cache(maxsize=None)
def check_field(P: int) -> Field:
    """A second field, with another prime, in which a reconstructed K is checked: rational
    reconstruction returns a rational congruent to the true one mod P, so a check in the same
    field cannot fail, even when the true numerator or denominator exceeded sqrt(P/2) and the
    rational is wrong (the SO-ARM101's 0.0304-type lengths gave -1.04*m5 for a 0.06 m lever)."""
    bits, k = LADDER[0]
    while True:
        k += 1
        prime = 24 * ((1 << bits) // 24 + k) + 1
        if prime != P and sp.isprime(prime):
            return Field(prime, math.isqrt(prime >> 1), {b: int(sp.sqrt_mod(b, prime)) for b in (2, 3)})


def fields():
    """The fields to try, smallest first: the first that holds the constants and reconstructs
    every coefficient is used."""
    yield MERSENNE
    for bits, k in LADDER:
        yield ladder_field(bits, k)


def inverse(x: int, field: Field = MERSENNE) -> int:
    return pow(x % field.P, -1, field.P)  # extended Euclid: far faster than Fermat at 1280 bits


def to_field(value, field: Field = MERSENNE) -> int:
    """An exact SymPy number (a rational, or one of Q(sqrt 2, sqrt 3)) in GF(P)."""
    value = sp.sympify(value)
    if value.is_Rational:
        return (int(value.p) * inverse(int(value.q), field)) % field.P
    return evaluate(value, {}, {}, field)


def circle_point(rng: random.Random, field: Field = MERSENNE) -> tuple[int, int]:
    """(cos, sin) of a random rational angle, in GF(P)."""
    P = field.P
    t = rng.randrange(1, P)
    den = inverse(1 + t * t, field)
    return ((1 - t * t) * den) % P, (2 * t * den) % P


def evaluate(expr, env: dict, cache: dict, field: Field = MERSENNE) -> int:
    """expr in GF(P); env maps symbols to field values; cache memoises numbers."""
    P = field.P
    if expr.is_Symbol:
        return env[expr]
    if expr.is_Number:
        if expr not in cache:
            cache[expr] = to_field(sp.Rational(expr), field)
        return cache[expr]
    if expr.is_Add:
        total = 0
        for arg in expr.args:
            total += evaluate(arg, env, cache, field)
        return total % P
    if expr.is_Mul:
        product = 1
        for arg in expr.args:
            product = (product * evaluate(arg, env, cache, field)) % P
        return product
    if expr.is_Pow and expr.exp.is_Integer:
        base = evaluate(expr.base, env, cache, field)
        e = int(expr.exp)
        return pow(base, e, P) if e >= 0 else pow(inverse(base, field), -e, P)
    if expr.is_Pow and expr.exp.is_Rational and expr.exp.q == 2 and expr.base.is_Integer and expr.base > 0:
        if expr not in cache:  # sqrt(n)^k
            root, e = field.root(int(expr.base)), int(expr.exp.p)
            cache[expr] = pow(root, e, P) if e >= 0 else pow(inverse(root, field), -e, P)
        return cache[expr]
    raise NotInField(f"cannot evaluate {expr} exactly")


def run(assignments, outputs, env: dict, field: Field = MERSENNE) -> list[int]:
    """Evaluate a pruned program and its outputs at one point."""
    env = dict(env)
    cache: dict = {}
    for a in assignments:
        env[a.symbol] = evaluate(a.expr, env, cache, field)
    return [evaluate(sp.sympify(o), env, cache, field) for o in outputs]


def rational(x: int, field: Field = MERSENNE) -> sp.Rational:
    """Rational reconstruction: the a/b with |a|, b < sqrt(P/2) and a = b x mod P."""
    bound = field.bound
    r0, r1, s0, s1 = field.P, x % field.P, 0, 1
    while r1 >= bound:
        quotient = r0 // r1
        r0, r1 = r1, r0 - quotient * r1
        s0, s1 = s1, s0 - quotient * s1
    if s1 == 0 or abs(s1) >= bound:
        raise NotInField("no small rational")
    return sp.Rational(r1, s1)


class Echelon:
    """A reduced row echelon basis over GF(P), grown one row at a time.

    Each basis row has a leading 1 in its pivot column and zeros in every other pivot
    column. A new row is reduced against the basis (dropped when nothing is left) and the
    basis against it: O(rank x columns) per row, so only the rows sampled are eliminated,
    not a tall matrix again and again. The result is the unique reduced form of the row space.
    """

    def __init__(self, n_cols: int, field: Field = MERSENNE):
        self.n_cols, self.field = n_cols, field
        self.pivots: list[int] = []  # increasing
        self.rows: list[list[int]] = []  # rows[r] belongs to pivots[r]

    def add(self, row) -> bool:
        """Adds row's new direction, if any; True when the rank grew."""
        P = self.field.P
        row = [v % P for v in row]
        for pivot, basis in zip(self.pivots, self.rows):
            k = row[pivot]
            if k:  # a basis row is zero left of its pivot: only the columns from there on change
                row[pivot:] = [(v - k * w) % P for v, w in zip(row[pivot:], basis[pivot:])]
        col = next((c for c, v in enumerate(row) if v), None)
        if col is None:
            return False
        inv = inverse(row[col], self.field)
        row[col:] = [(v * inv) % P for v in row[col:]]
        for basis in self.rows:
            k = basis[col]
            if k:
                basis[col:] = [(v - k * w) % P for v, w in zip(basis[col:], row[col:])]
        at = bisect.bisect(self.pivots, col)
        self.pivots.insert(at, col)
        self.rows.insert(at, row)
        return True

