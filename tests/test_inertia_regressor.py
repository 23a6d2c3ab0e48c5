"""The factored inertia regressor against the straightforward one it replaced.

The straightforward Y_m: for each joint k, Newton-Euler with a unit acceleration of joint k
(zero velocity, no gravity) and the body regressor of every link carried back to every
joint (N(N+1)/2 x 10N entries, O(N^3) code). It is built here, in the test, from the
recursion's public pieces, and compared exactly (over GF(P), no tolerance) with:
  - phi over the unit-acceleration motions (derivation/inertia.py), every one of the 10N
    columns, so every sign of the bilinear forms is checked on every example arm;
  - the base set the generator now takes from the full regressor without gravity.
The emitted C is checked against the numeric Lagrangian in test_generated_c.py.
"""

from __future__ import annotations

import random

import pytest
import sympy as sp
from conftest import EXAMPLES, derive

from dyngen.derivation.inertia import motion_index, phi, stacked_regressor, stacked_row
from dyngen.derivation.models import Derivation, Input, Model
from dyngen.derivation.newton_euler import Chain, joint_symbols
from dyngen.derivation.program import Program
from dyngen.description import load_robot
from dyngen.reduction import exact
from dyngen.reduction.base import reduce_model

ARMS = {p.stem: p for p in EXAMPLES}


def straightforward_inertia_regressor(robot) -> Model:
    """Y_m over all 10N standard parameters, rows M[j][k] (j <= k), as dyngen printed it before."""
    program, sym = Program(), joint_symbols(robot)
    chain = Chain(robot, program, sym)
    n, zero = robot.dof, [0] * robot.dof
    columns = [chain.regressor_columns(chain.forward(zero, [int(j == k) for j in range(n)], [0, 0, 0]))
               for k in range(n)]
    rows = [columns[k][j] for j in range(n) for k in range(j, n)]
    return Model("regressor_inertia", [Input("q", sym.q, "")], [x for row in rows for x in row],
                 (len(rows), 10 * n), "", program, sym.trig)


def random_env(model, rng) -> dict:
    """Exact values of the model's inputs: rational points of the circle for sin/cos, any field
    element for a prismatic joint's q."""
    env, angles = {}, {}
    for symbol, (joint, fn) in model.trig.items():
        angles.setdefault(joint, {})[fn] = symbol
    for joint in sorted(angles):
        env[angles[joint]["cos"]], env[angles[joint]["sin"]] = exact.circle_point(rng)
    for symbol in model.inputs[0].symbols:
        env[symbol] = rng.randrange(exact.P)
    return env


@pytest.fixture(scope="module", params=sorted(ARMS))
def arm(request):
    robot = load_robot(ARMS[request.param])
    return robot, Derivation(robot), straightforward_inertia_regressor(robot)


def test_phi_over_unit_accelerations_is_the_inertia_regressor_exactly(arm):
    robot, derivation, old = arm
    n = robot.dof
    motions = derivation.unit_accelerations()
    assert motions.shape == (n * (n + 1) // 2, 6)
    rng = random.Random(7)
    for _ in range(3):
        env = random_env(old, rng)  # the same sin, cos and q for both programs
        want = exact.run(old.assignments, old.outputs, env)
        flat = exact.run(motions.assignments, motions.outputs, env)
        S = [flat[6 * k: 6 * k + 6] for k in range(len(flat) // 6)]
        got = stacked_regressor(S, range(10 * n), n)
        assert [g % exact.P for g in got] == want


def test_inertia_base_set_from_the_regressor_without_gravity_is_the_one_from_y_m(arm):
    robot, derivation, old = arm
    assert reduce_model(derivation.regressor("full_without_gravity"), "inertia") == reduce_model(old)


def test_phi_is_the_kinetic_energy_form():
    """m v_j.v_k + h.(v_j x w_k + v_k x w_j) + w_j^T J w_k: the bilinear form of 2T, checked
    symbolically on arbitrary motions and parameters (kinds in the standard order)."""
    a, b = sp.symbols("a0:6"), sp.symbols("b0:6")
    m, hx, hy, hz, xx, xy, xz, yy, yz, zz = s = sp.symbols("m hx hy hz XX XY XZ YY YZ ZZ")
    wa, va, wb, vb = sp.Matrix(a[:3]), sp.Matrix(a[3:]), sp.Matrix(b[:3]), sp.Matrix(b[3:])
    h, J = sp.Matrix([hx, hy, hz]), sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    # kinetic energy of a rigid body moving with (w, v at O): T = 1/2 (m v.v + 2 v.(w x h) + w^T J w)
    polar = m * va.dot(vb) + va.dot(wb.cross(h)) + vb.dot(wa.cross(h)) + (wa.T * J * wb)[0]
    assert sp.expand(polar - sum(s[k] * phi(k, a, b) for k in range(10))) == 0


def test_layout_helpers():
    n = 4
    rows = [stacked_row(j, k, n) for j in range(n) for k in range(j, n)]
    assert rows == list(range(n * (n + 1) // 2))
    assert [motion_index(i, j) for i in range(n) for j in range(i + 1)] == list(range(n * (n + 1) // 2))


class Counter:
    """A number that only counts the multiplications and additions made with it."""

    mul = add = 0

    def __mul__(self, other):
        Counter.mul += 1
        return Counter()

    def __add__(self, other):
        Counter.add += 1
        return Counter()

    __sub__ = __add__


def test_operation_count_is_the_loop_trips_times_the_body_plus_the_motions():
    """The header's count of Y_m equals the motions' straight-line count plus the products and
    sums that evaluating every filled entry with phi makes (counted by brute force here)."""
    from dyngen.emission.c_code import straight_line
    from dyngen.emission.opcount import count_all
    robot, bases, emitted = derive(ARMS["lwr"])
    motions = Derivation(robot).unit_accelerations()
    straight = straight_line(robot.name, robot.joint_models, motions, motions.outputs).ops + count_all(motions.outputs)
    n = robot.dof
    Counter.mul = Counter.add = 0
    stacked_regressor([[Counter() for _ in range(6)] for _ in range(n * (n + 1) // 2)], bases["inertia"].pivots, n)
    reported = next(f.ops for f in emitted.functions if f.name == "lwr_regressor_inertia")
    assert (reported.mul, reported.add) == (straight.mul + Counter.mul, straight.add + Counter.add)
    assert Counter.mul > 1000  # the loop is most of it: O(n^3) products for an O(n^3) output
