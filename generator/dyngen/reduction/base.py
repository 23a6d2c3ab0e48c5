"""Base coefficients: prune never-appearing parameters, regroup dependent ones, minimally.

Y(x) s = Y_b(x) pi with pi = K s, where Y_b holds the independent columns of Y (the
first ones in the canonical parameter order, link 1 first, so a parameter of link j+1
is grouped into one of link j as in Gautier-Khalil) and K = [I | beta] is exact and
rational. The number of base coefficients is the exact rank of Y over random states.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

import sympy as sp

from . import exact


@dataclass(frozen=True)
class BaseSet:
    """A minimal regrouping of the standard parameters for one regressor."""

    kind: str  # "gravity" | "inertia" | "full"
    pivots: tuple[int, ...]  # indices into s of the columns kept in Y_b
    K: tuple[tuple[sp.Rational, ...], ...]  # rank x 10N, pi = K s

    @property
    def rank(self) -> int:
        return len(self.pivots)

    def coefficients(self, s_symbols) -> list[sp.Expr]:
        return [sp.Add(*(k * s for k, s in zip(row, s_symbols) if k != 0)) for row in self.K]

    def appearing(self) -> list[int]:
        """Indices of standard parameters that appear in some coefficient."""
        return sorted({j for row in self.K for j, k in enumerate(row) if k != 0})


class SampledRegressor:
    """Rows of a regressor evaluated exactly at random states."""

    def __init__(self, assignments, outputs_per_state, n_cols, sample_env, seed=0):
        self.assignments, self.outputs = assignments, outputs_per_state
        self.n_cols, self.sample_env = n_cols, sample_env
        self.rng = random.Random(seed)

    def rows(self, n_states: int) -> list[list[int]]:
        rows = []
        for _ in range(n_states):
            values = exact.run(self.assignments, [x for row in self.outputs for x in row], self.sample_env(self.rng))
            rows.extend(values[r * self.n_cols:(r + 1) * self.n_cols] for r in range(len(self.outputs)))
        return rows


QUIET_STATES = 3  # fresh states in a row that must add nothing before the rank is taken as found


def reduce(kind: str, sampled: SampledRegressor) -> BaseSet:
    """Exact rank and regrouping; samples one state at a time until QUIET_STATES fresh
    states in a row add nothing (each would, with probability ~1 - 1e-30, if the row space
    were not complete). Long chains whose coefficients outgrow the first prime field are
    reduced again in a larger one (the result, unique, is the same)."""
    for prime in exact.PRIMES:
        with exact.prime_field(prime):
            try:
                return _reduce(kind, sampled)
            except exact.Reconstruction:
                continue
    raise exact.Reconstruction(f"{kind}: the regrouping coefficients need more than "
                               f"{exact.PRIMES[-1].bit_length() // 2} bits")


def _reduce(kind: str, sampled: SampledRegressor) -> BaseSet:
    echelon = exact.Echelon(sampled.n_cols)
    quiet = 0
    while quiet < QUIET_STATES:
        grew = [echelon.add(row) for row in sampled.rows(1)]
        quiet = 0 if any(grew) else quiet + 1
    pivots, reduced = echelon.pivots, echelon.rows
    K = tuple(tuple(exact.rational(v) for v in row) for row in reduced)
    _check(kind, sampled, pivots, K)
    return BaseSet(kind, tuple(pivots), K)


def _check(kind, sampled, pivots, K):
    """Y == Y_b K exactly at fresh states (a wrong rational reconstruction fails here)."""
    Kp = [[exact.to_field(k) for k in row] for row in K]
    for row in sampled.rows(2):
        for j in range(sampled.n_cols):
            rebuilt = sum(row[b] * Kp[r][j] for r, b in enumerate(pivots)) % exact.P
            if rebuilt != row[j] % exact.P:
                raise exact.Reconstruction(f"{kind}: regrouping check failed at column {j}")


def reduce_model(model, kind: str | None = None) -> BaseSet:
    """Reduce a full regressor model (derivation.models.Derivation.regressor); kind names the
    BaseSet (default: from the model's name).

    The inertia matrix's base set comes from the full regressor with gravity zero, not from
    Y_m: Y_m(q) s = 0 for all q iff Y(q, qd, qdd; g = 0) s = 0 for all states (M(q) s
    determines the Coriolis terms), so both have the same row space, hence the same pivots and
    K. That regressor has n rows per state and O(n^2) code; Y_m has n(n+1)/2 and O(n^3)."""
    trig = model.trig
    angle_of = {}
    for symbol, (joint, fn) in trig.items():
        angle_of.setdefault(joint, {})[fn] = symbol
    free_inputs = [s for inp in model.inputs for s in inp.symbols if s not in trig]

    def sample_env(rng):
        env = {}
        for joint in sorted(angle_of):
            cos_value, sin_value = exact.circle_point(rng)
            env[angle_of[joint]["cos"]] = cos_value
            env[angle_of[joint]["sin"]] = sin_value
        for symbol in free_inputs:  # prismatic q, qd, qdd, gravity symbols
            env[symbol] = rng.randrange(exact.P)
        return env

    rows, cols = model.shape
    per_state = [model.outputs[r * cols:(r + 1) * cols] for r in range(rows)]
    sampled = SampledRegressor(model.assignments, per_state, cols, sample_env)
    return reduce(kind or model.name.replace("regressor_", ""), sampled)
