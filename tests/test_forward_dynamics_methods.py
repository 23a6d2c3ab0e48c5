"""Both derivations of forward dynamics (the articulated-body algorithm and the L D L^T of M),
evaluated straight from their SymPy programs on every example arm, against Pinocchio's aba
and against FD(ID(qdd)) = qdd with the generated rnea; and the emitted forward_dynamics is the
one with fewer operations (what docs/controller-functions.md promises)."""

from __future__ import annotations

import numpy as np
from oracles import pinocchio_control as pin_control
from oracles.random_params import random_parameters
from test_generated_c import random_state, rel_err

from dyngen.derivation.evaluate import evaluate
from dyngen.derivation.forward_dynamics import candidates
from dyngen.derivation.models import Derivation
from dyngen.generate import operations

TOL = 1e-9


def test_both_methods_match_pinocchio_aba_and_invert_rnea(built):
    models = candidates(Derivation(built.robot), built.bases["full"])  # as emitted: the grouped parameters
    rng = np.random.default_rng(7)
    p = random_parameters(built.robot.dof, seed=8)
    s = built.c("standard_from_dynamic", p)
    worst = {}
    for _ in range(4):  # 40-digit evaluation of ~2000 assignments: a few states suffice for the method
        q, qd, qdd = random_state(built, rng)
        tau = built.c("rnea", q, qd, qdd, s)
        aba = pin_control.forward_dynamics(built.arm, p, q, qd, tau)
        for method, model in models.items():
            got = evaluate(model, built.robot.joint_models, {"q": q, "qd": qd, "tau": tau, "s": s})
            for check, want in (("Pinocchio aba", aba), ("FD(ID(qdd)) = qdd", qdd)):
                worst[(method, check)] = max(worst.get((method, check), 0.0), rel_err(got, want))
    assert all(err < TOL for err in worst.values()), worst


def test_the_emitted_method_has_fewer_operations(built):
    models = candidates(Derivation(built.robot), built.bases["full"])  # as emitted: the grouped parameters
    counts = {method: operations(model) for method, model in models.items()}
    fewest = min(counts, key=lambda m: (counts[m], m != "ldlt"))
    source = built.emitted.files[f"{built.name}_forward.c"]
    sections = {"articulated_body": "articulated inertia */", "ldlt": "M = L D L^T */"}
    assert [m for m, marker in sections.items() if marker in source] == [fewest], counts
    spec = next(f for f in built.c.manifest["functions"] if f["name"] == f"{built.name}_forward_dynamics")
    ops = spec["ops"]
    assert ops["mul"] + ops["add"] + ops["div"] <= min(counts.values()), (counts, ops)
