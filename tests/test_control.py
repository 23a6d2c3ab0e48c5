"""control() and control_with_jacobian(), one call per control cycle, on every example arm:
their g, M, c against the separate generated functions (rnea, gravity, mass_matrix) and against
the numpy Lagrangian oracle (c from the Christoffel symbols); their J and Jdot qd against
Pinocchio. Random states and random consistent parameters, 1e-9 relative."""

from __future__ import annotations

import numpy as np
from oracles import kinematics as kin
from oracles import lagrangian as lag
from oracles.random_params import random_parameters

N_STATES = 20
TOL = 1e-9


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, float(np.max(np.abs(b)))))


def random_state(built, rng):
    n = built.robot.dof
    q = rng.uniform(-np.pi, np.pi, n)
    for i, joint in enumerate(built.robot.joints):
        if not joint.revolute:
            q[i] = rng.uniform(0.2, 1.0)
    return q, rng.uniform(-2, 2, n)


def test_control_matches_the_separate_functions_and_the_oracles(built):
    rng = np.random.default_rng(7)
    n = built.robot.dof
    p = random_parameters(n, seed=13)
    s = built.c("standard_from_dynamic", p)
    tool = kin.tool_matrix(built.yaml)
    model, data = kin.pinocchio_model(built.arm, tool)
    worst = {}
    for _ in range(N_STATES):
        q, qd = random_state(built, rng)
        g, M, c = built.c("control", q, qd, s)
        g2, M2, c2, J, jdot_qd = built.c("control_with_jacobian", q, qd, s)
        pin_side = kin.pinocchio_kinematics(model, data, n, q, qd)
        rnea_no_qdd = built.c("rnea", q, qd, np.zeros(n), s)
        checks = {
            "g / gravity()": (g, built.c("gravity", q, s)),
            "M / mass_matrix()": (M, built.c("mass_matrix", q, s)),
            "c + g / rnea(q, qd, 0)": (c + g, rnea_no_qdd),
            "g / lagrangian": (g, lag.gravity(built.arm, q, p)),
            "M / lagrangian": (M, lag.mass_matrix(built.arm, q, p)),
            "c / lagrangian": (c, lag.coriolis(built.arm, q, qd, p)),
            "with_jacobian g, M, c": (np.concatenate([g2, M2.ravel(), c2]), np.concatenate([g, M.ravel(), c])),
            "with_jacobian J / pinocchio": (J, pin_side["jacobians"][-1]),
            "with_jacobian jdot_qd / pinocchio": (jdot_qd, pin_side["jdot_qd"]),
        }
        for name, (got, want) in checks.items():
            worst[name] = max(worst.get(name, 0.0), rel_err(got, want))
    bad = {k: v for k, v in worst.items() if not v < TOL}
    assert not bad, bad


def test_control_computes_each_sine_and_cosine_once(lwr):
    """The point of the function: one pair per revolute joint, however many outputs."""
    ops = {f.name: f.ops for f in lwr.emitted.functions}
    revolute = sum(j.revolute for j in lwr.robot.joints)
    assert ops["lwr_control"].trig == ops["lwr_rnea"].trig <= 2 * revolute
    separate = sum(ops[f"lwr_{name}"].mul for name in ("gravity", "mass_matrix", "rnea"))
    assert ops["lwr_control"].mul < separate
