"""The values embedded in the generated self-test (<robot>_selftest.c).

Fixed link parameters (the YAML's nominal ones, or fixed consistent ones when it has none)
and a few fixed states; the expected tau, g(q) and M(q) are computed by evaluating the
generator's own programs in 40-digit arithmetic (derivation/evaluate.py), not by running
the emitted C. The self-test then checks the compiled C, including the regressors times
the base coefficients (different programs), against them.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..derivation.evaluate import evaluate
from ..parameters import PER_LINK

N_STATES = 3
GRAVITY_SYMBOL_VALUES = (9.81, -2.5, 1.25)  # values for symbolic gravity entries, in order of the symbols
# Relative tolerance, normwise: max_k |got_k - want_k| <= tol * max_k |want_k| (docs/conventions.md).
TOLERANCE = {"double": 1e-9, "float": 2e-5}


@dataclass
class SelfTestData:
    p: list  # dynamic parameters
    gravity: list  # values of the gravity symbols (empty when gravity is numeric)
    states: list  # [(q, qd, qdd)]
    tau: list  # per state, rnea(q, qd, qdd)
    g: list  # per state, gravity(q)
    M: list  # per state, mass_matrix(q), row-major

    def as_dict(self) -> dict:
        """For manifest.json, so that anyone can check the embedded values."""
        return {"p": self.p, "gravity_symbols": self.gravity,
                "states": [{"q": q, "qd": qd, "qdd": qdd, "tau": tau, "g": g, "M": M}
                           for (q, qd, qdd), tau, g, M in zip(self.states, self.tau, self.g, self.M)]}


def fixed_parameters(robot) -> list[float]:
    """The YAML's nominal parameters, or fixed physically consistent ones (m > 0, inertia
    positive definite and satisfying the triangle inequality) when the YAML has none."""
    if robot.nominal:
        return [float(v) for link in robot.nominal for v in link.as_tuple()]
    p = []
    for i in range(robot.dof):
        m = 1.0 + 0.5 * i
        p += [m, 0.01 * (i + 1), -0.02, 0.05, 0.02 * m, 0.001, -0.002, 0.03 * m, 0.0015, 0.025 * m]
    return p


def fixed_states(robot) -> list[tuple[list, list, list]]:
    """Deterministic states with all signs and no special angles: entries k/4 - 1.25 and the like."""
    n = robot.dof
    return [([((7 * i + 3 * k) % 11 - 5) / 4 for i in range(n)],
             ([((5 * i + 2 * k) % 9 - 4) / 4 for i in range(n)]),
             ([((3 * i + 5 * k) % 13 - 6) / 3 for i in range(n)]))
            for k in range(N_STATES)]


def selftest_data(robot, derivation, models: dict) -> SelfTestData:
    """models: the rnea, gravity and mass_matrix Models the C was printed from."""
    joint_models = robot.joint_models
    p = fixed_parameters(robot)
    assert len(p) == PER_LINK * robot.dof
    s = evaluate(derivation.standard_from_dynamic(), joint_models, {"p": p})
    gravity = [GRAVITY_SYMBOL_VALUES[k % len(GRAVITY_SYMBOL_VALUES)] for k in range(len(robot.gravity_symbols))]
    states = fixed_states(robot)
    tau, g, M = [], [], []
    for q, qd, qdd in states:
        common = {"q": q, "s": s, "gravity": gravity}
        tau.append(evaluate(models["rnea"], joint_models, {**common, "qd": qd, "qdd": qdd}))
        g.append(evaluate(models["gravity"], joint_models, common))
        M.append(evaluate(models["mass_matrix"], joint_models, common))
    return SelfTestData(p, gravity, states, tau, g, M)


def c_numbers(values, per_line: int = 0, indent: int = 8) -> str:
    """Round-trip exact C literals (Python's shortest repr), so the output is deterministic;
    per_line > 0 breaks the list after every per_line numbers (one link, one matrix row)."""
    texts = [repr(float(v)) for v in values]
    if per_line <= 0:
        return ", ".join(texts)
    lines = [", ".join(texts[k:k + per_line]) for k in range(0, len(texts), per_line)]
    return (",\n" + " " * indent).join(lines)
