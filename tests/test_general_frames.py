"""DH twists that are not multiples of pi/2 (exact pi/4, pi/3, pi/6, pi/12 and numeric ones):
the base counts equal the numerical rank of Pinocchio's regressor and the generated C's rnea,
gravity and M equal Pinocchio's (built from the oracles' own float reading of the YAML)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from conftest import build_arm
from oracles import pinocchio_arm as pin_arm
from oracles.random_params import random_parameters

from dyngen.reduction import exact

ARMS = {
    # name: (convention, rows (type, a, alpha, d, theta))
    "twist_pi4": ("modified", [("revolute", 0, 0, 0.3, 0), ("revolute", 0.1, '"pi/4"', 0, 0),
                               ("revolute", 0.4, '"-pi/4"', 0.1, 0), ("revolute", 0.05, '"pi/2"', 0.2, 0)]),
    "twist_pi3_pi6": ("modified", [("revolute", 0, 0, 0, 0), ("revolute", 0.1, '"pi/3"', 0.05, 0),
                                   ("prismatic", 0.2, '"pi/6"', 0.1, '"pi/3"'), ("revolute", 0.1, '"5*pi/12"', 0, 0)]),
    "twist_numeric": ("standard", [("revolute", 0.1, 0.3, 0.3, 0), ("revolute", 0.4, -1.1, 0, 0.2),
                                   ("revolute", 0.2, 2.5, 0.1, 0), ("prismatic", 0.05, 0.7, 0.2, 0.4)]),
}
DENSE = ['"pi/4"', '"pi/3"', '"pi/6"', '0.3', '"-pi/4"', '"2*pi/3"', '"pi/12"', '-0.7', '"pi/4"', '"5*pi/12"',
         '"pi/3"', '1.1']


def dense_rows(n):
    return [("prismatic" if i == 5 else "revolute", round(0.05 + 0.01 * i, 2), DENSE[i], 0.1 if i % 2 else 0.0,
             0.2 if i == 5 else 0) for i in range(n)]


def write_yaml(folder, name, convention, rows):
    lines = [f"name: {name}", f"dh: {convention}", "gravity: [0, 0, -9.81]", "joints:"]
    lines += [f"  - {{type: {t}, a: {a}, alpha: {al}, d: {d}, theta: {th}}}" for t, a, al, d, th in rows]
    lines += ["parameters:", "  nominal:"]
    lines += [f"    - {{m: {1 + 0.1 * i}, c: [0.01, -0.02, 0.03], I: [0.02, 0.001, 0, 0.03, 0, 0.01]}}"
              for i in range(len(rows))]
    path = folder / f"{name}.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, float(np.max(np.abs(b)))))


def check_against_pinocchio(built, n_states=20):
    for kind in ("gravity", "inertia", "full"):
        assert built.bases[kind].rank == pin_arm.regressor_rank(built.arm, kind, n_samples=30, seed=3), kind
    rng = np.random.default_rng(4)
    n = built.robot.dof
    p = random_parameters(n, seed=5)
    s = built.c("standard_from_dynamic", p)
    pi = built.c("pi_full", p)
    for _ in range(n_states):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)
        tau = pin_arm.rnea(built.arm, p, q, qd, qdd)
        assert rel_err(built.c("rnea", q, qd, qdd, s), tau) < 1e-9
        assert rel_err(built.c("regressor", q, qd, qdd) @ pi, tau) < 1e-9
        assert rel_err(built.c("gravity", q, s), pin_arm.gravity(built.arm, p, q)) < 1e-9
        assert rel_err(built.c("mass_matrix", q, s), pin_arm.mass_matrix(built.arm, p, q)) < 1e-9


@pytest.mark.parametrize("name", sorted(ARMS))
def test_general_twists_match_pinocchio(name, tmp_path):
    convention, rows = ARMS[name]
    check_against_pinocchio(build_arm(write_yaml(tmp_path, name, convention, rows), tmp_path))


def test_dense_chain_of_general_twists_matches_pinocchio(tmp_path):
    check_against_pinocchio(build_arm(write_yaml(tmp_path, "dense7", "modified", dense_rows(7)), tmp_path), 10)


def test_exact_twist_gives_exact_coefficients(tmp_path):
    """alpha = pi/4 keeps sqrt(2) exact in the base coefficients (not a rounded rational)."""
    convention, rows = ARMS["twist_pi4"]
    built = build_arm(write_yaml(tmp_path, "twist_pi4", convention, rows), tmp_path)
    numbers = {k for row in built.bases["full"].K for k in row}
    assert any(k.has(sp.sqrt(2)) for k in numbers)


def test_field_ladder_primes():
    """Each ladder prime is prime, 1 mod 24, and holds square roots of 2 and 3."""
    for bits, k in exact.LADDER:
        field = exact.ladder_field(bits, k)
        assert sp.isprime(field.P) and field.P % 24 == 1
        assert all(pow(r, 2, field.P) == b for b, r in field.roots.items())
