"""Which parameters the coefficients determine: alone, only in groups, or not at all.

A standard parameter s_j is identifiable alone when e_j lies in the row space of K
(some combination of coefficients equals it). K is in reduced echelon form, so that is
the case exactly when j is a pivot whose row holds nothing else. It is absent when no
coefficient holds it.
A dynamic parameter is absent when none of the standard parameters it feeds appears, and
alone when every standard parameter it is computed from is (c_x = mx/m needs m and mx).
The paper's p' is everything not absent.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..parameters import PER_LINK, dynamic_name, standard_name, standard_from_dynamic_link

# Standard parameters (indices within a link) that each dynamic parameter is recovered from.
_RECOVERED_FROM = {
    0: (0,), 1: (0, 1), 2: (0, 2), 3: (0, 3),
    4: (0, 2, 3, 4), 5: (0, 1, 2, 5), 6: (0, 1, 3, 6), 7: (0, 1, 3, 7), 8: (0, 2, 3, 8), 9: (0, 1, 2, 9),
}


@dataclass(frozen=True)
class Identifiability:
    alone: tuple[str, ...]
    grouped: tuple[str, ...]
    absent: tuple[str, ...]


def _feeds() -> dict:
    """dynamic index within a link -> standard indices whose expression contains it."""
    p = sp.symbols("p0:10")
    s = standard_from_dynamic_link(p)
    return {k: tuple(j for j in range(PER_LINK) if p[k] in sp.sympify(s[j]).free_symbols) for k in range(PER_LINK)}


def classify(base, n_links: int) -> tuple[Identifiability, Identifiability]:
    """(standard, dynamic) classification for one BaseSet."""
    appearing = set(base.appearing())
    alone = {j for j, row in zip(base.pivots, base.K) if sum(1 for k in row if k != 0) == 1}
    standard = _split([standard_name(i + 1, k) for i in range(n_links) for k in range(PER_LINK)],
                      lambda j: j in alone, lambda j: j in appearing)
    feeds = _feeds()

    def dyn_alone(j):
        link, k = divmod(j, PER_LINK)
        return all(link * PER_LINK + r in alone for r in _RECOVERED_FROM[k])

    def dyn_appears(j):
        link, k = divmod(j, PER_LINK)
        return any(link * PER_LINK + r in appearing for r in feeds[k])

    dynamic = _split([dynamic_name(i + 1, k) for i in range(n_links) for k in range(PER_LINK)],
                     dyn_alone, dyn_appears)
    return standard, dynamic


def _split(names, is_alone, appears) -> Identifiability:
    alone = tuple(n for j, n in enumerate(names) if appears(j) and is_alone(j))
    grouped = tuple(n for j, n in enumerate(names) if appears(j) and not is_alone(j))
    absent = tuple(n for j, n in enumerate(names) if not appears(j))
    return Identifiability(alone, grouped, absent)
