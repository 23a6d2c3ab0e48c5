"""Base coefficients: prune never-appearing parameters, regroup dependent ones, minimally.

Y(x) s = Y_b(x) pi with pi = K s, where Y_b holds the independent columns of Y (the
first ones in the canonical parameter order, link 1 first, so a parameter of link j+1
is grouped into one of link j as in Gautier-Khalil) and K = [I | beta] is exact and
exact: rational, or in Q(sqrt 2, sqrt 3) when a twist is a multiple of pi/12 that is not one
of pi/2 (reduction/exact.py). The number of base coefficients is the exact rank of Y over
random states.
"""

from __future__ import annotations

import itertools
import math
import random
from dataclasses import dataclass

import sympy as sp

from . import exact


@dataclass(frozen=True)
class BaseSet:
    """A minimal regrouping of the standard parameters for one regressor."""

    kind: str  # "gravity" | "inertia" | "full"
    pivots: tuple[int, ...]  # indices into s of the columns kept in Y_b
    K: tuple[tuple[sp.Expr, ...], ...]  # rank x 10N, pi = K s (exact numbers)

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
        self.n_cols, self.sample_env, self.seed = n_cols, sample_env, seed
        self.restart(exact.MERSENNE)

    def restart(self, field: exact.Field):
        """Sample in `field` from the first state again."""
        self.field, self.rng = field, random.Random(self.seed)

    def rows(self, n_states: int) -> list[list[int]]:
        rows = []
        for _ in range(n_states):
            values = exact.run(self.assignments, [x for row in self.outputs for x in row],
                               self.sample_env(self.rng, self.field), self.field)
            rows.extend(values[r * self.n_cols:(r + 1) * self.n_cols] for r in range(len(self.outputs)))
        return rows


QUIET_STATES = 3  # fresh states in a row that must add nothing before the rank is taken as found


def reduce(kind: str, sampled: SampledRegressor) -> BaseSet:
    """Exact rank and regrouping in the first field (exact.fields) that holds the arm's
    constants and whose prime is large enough to reconstruct every coefficient of K."""
    for field in exact.fields():
        try:
            return _reduce_in(kind, sampled, field)
        except exact.NotInField:
            continue
    raise exact.NotInField(f"{kind}: the coefficients are too large to reconstruct exactly")


def _reduce_in(kind, sampled, field) -> BaseSet:
    """K in Q(sqrt b, b in the roots used): one echelon per embedding (choice of the roots'
    signs); K = sum over square-free products r of the roots of k_r r, and k_r, a rational, is
    the signed mean of the embeddings' K divided by r (characters of the group of signs)."""
    field.used = set()
    pivots, first = _echelon(sampled, field)
    used = sorted(field.used)
    if not used:
        K = tuple(tuple(exact.rational(v, field) for v in row) for row in first)
        _check(kind, sampled, pivots, K, exact.check_field(field.P))
        return BaseSet(kind, tuple(pivots), K)
    embeddings = {}
    for signs in itertools.product((1, -1), repeat=len(used)):
        other = field.embedding(dict(zip(used, signs)))
        other_pivots, reduced = (pivots, first) if all(x == 1 for x in signs) else _echelon(sampled, other)
        if other_pivots != pivots:
            raise AssertionError(f"{kind}: the embeddings of the constants disagree on the rank")
        embeddings[signs] = reduced
    P, count = field.P, len(embeddings)
    subsets = []  # (characters per embedding, 1/(count root) in GF(P), the root as a SymPy number)
    for subset in itertools.product((0, 1), repeat=len(used)):
        root = math.prod(field.roots[b] for b, take in zip(used, subset) if take) % P
        characters = [math.prod(s for s, take in zip(signs, subset) if take) for signs in embeddings]
        subsets.append((characters, exact.inverse(count * root, field),
                        sp.sqrt(math.prod(b for b, take in zip(used, subset) if take))))
    tables = list(embeddings.values())
    K = []
    for r, row in enumerate(first):
        K_row = []
        for j in range(len(row)):
            total = []
            for characters, scale, root in subsets:
                mean = sum(ch * table[r][j] for ch, table in zip(characters, tables)) * scale % P
                if mean:
                    total.append(exact.rational(mean, field) * root)
            K_row.append(sp.Add(*total))
        K.append(tuple(K_row))
    K = tuple(K)
    check = exact.check_field(field.P)
    for signs in embeddings:
        _check(kind, sampled, pivots, K, check.embedding(dict(zip(used, signs))))
    return BaseSet(kind, tuple(pivots), K)


def _echelon(sampled, field):
    """Samples one state at a time until QUIET_STATES fresh states in a row add nothing (each
    would, with probability ~1 - 1e-30, if the row space were not complete)."""
    sampled.restart(field)
    echelon = exact.Echelon(sampled.n_cols, field)
    quiet = 0
    while quiet < QUIET_STATES:
        grew = [echelon.add(row) for row in sampled.rows(1)]
        quiet = 0 if any(grew) else quiet + 1
    return echelon.pivots, echelon.rows


def _check(kind, sampled, pivots, K, field=None):
    """Y == Y_b K exactly at fresh states, in another prime's field than the reconstruction's
    (exact.check_field: a wrong rational reconstruction fails here, and the next field is tried)."""
    field = field or sampled.field
    sampled.field = field
    P = field.P
    Kp = [[exact.to_field(k, field) for k in row] for row in K]
    for row in sampled.rows(2):
        for j in range(sampled.n_cols):
            rebuilt = sum(row[b] * Kp[r][j] for r, b in enumerate(pivots)) % P
            if rebuilt != row[j] % P:  # a coefficient too large for this prime: the next one is tried
                raise exact.NotInField(f"{kind}: regrouping check failed at column {j}")


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

    def sample_env(rng, field):
        env = {}
        for joint in sorted(angle_of):
            cos_value, sin_value = exact.circle_point(rng, field)
            env[angle_of[joint]["cos"]] = cos_value
            env[angle_of[joint]["sin"]] = sin_value
        for symbol in free_inputs:  # prismatic q, qd, qdd, gravity symbols
            env[symbol] = rng.randrange(field.P)
        return env

    rows, cols = model.shape
    per_state = [model.outputs[r * cols:(r + 1) * cols] for r in range(rows)]
    sampled = SampledRegressor(model.assignments, per_state, cols, sample_env)
    return reduce(kind or model.name.replace("regressor_", ""), sampled)
