"""The values embedded in the generated self-test (<robot>_selftest.c).

Fixed link parameters (the YAML's nominal ones, or fixed consistent ones when it has none),
fixed friction values and a few fixed states; the expected output of every function of the
catalogue is computed by evaluating the generator's own programs in 40-digit arithmetic
(derivation/evaluate.py; friction by its law), not by running the emitted C. The self-test
then checks the compiled C against them; each regressor times its base coefficients
(different programs) against the values of the function it factors (catalogue Check).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mpmath

from ..catalogue import BY_NAME, FUNCTIONS
from ..terms.friction import FRICTION_FIELDS, friction_torque
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
    f: list  # friction values per joint (terms/friction.py FRICTION_FIELDS)
    states: list  # [(q, qd, qdd)]
    once: dict  # function name -> expected output, for the functions of p alone
    per_state: dict  # function name -> [expected output per state]

    def as_dict(self) -> dict:
        """For manifest.json, so that anyone can check the embedded values."""
        return {"p": self.p, "gravity_symbols": self.gravity, "f": self.f,
                "states": [{"q": q, "qd": qd, "qdd": qdd, "tau": self.per_state["rnea"][k],
                            "g": self.per_state["gravity"][k], "M": self.per_state["mass_matrix"][k],
                            "friction": self.per_state["friction"][k]}
                           for k, (q, qd, qdd) in enumerate(self.states)],
                "expected": self.once}


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


def fixed_friction(dof: int) -> list[float]:
    """Every joint's friction fields (terms/friction.py): values 0.5 + 0.25 j and the like;
    velocity scales 0.02 to 0.3, every other one <= 0 in turn on the joints (the plain sign, no
    Stribeck term), so every branch of the C is run."""
    f = []
    for j in range(dof):
        for k, field in enumerate(FRICTION_FIELDS):
            if field.kind == "value":
                f.append(0.5 + 0.25 * j - 0.1 * k)
            else:
                f.append(0.0 if (j + k) % 3 == 2 else 0.02 * (k + 1))
    return f


def friction_torques(qd, f) -> list[float]:
    """The friction terms' laws (terms/friction.py) in 40-digit arithmetic."""
    with mpmath.workdps(40):
        return [float(x) for x in friction_torque(mpmath, [mpmath.mpf(v) for v in qd], [mpmath.mpf(x) for x in f])]


def selftest_data(robot, programs: dict) -> SelfTestData:
    """programs: catalogue name -> (derivation Model, outputs) the C was printed from."""
    joint_models = robot.joint_models
    p = fixed_parameters(robot)
    assert len(p) == PER_LINK * robot.dof
    gravity = [GRAVITY_SYMBOL_VALUES[k % len(GRAVITY_SYMBOL_VALUES)] for k in range(len(robot.gravity_symbols))]
    f = fixed_friction(robot.dof)
    states = fixed_states(robot)
    direct = [fn for fn in FUNCTIONS if not fn.check.expected]  # in catalogue order: rnea before what takes
    # its output as tau (selftest_checks passes rnea_out)
    once = {fn.name: evaluate(programs[fn.name][0], joint_models, {"p": p}) for fn in direct if not fn.state}
    s = once["standard_from_dynamic"]
    per_state = {}
    for fn in direct:
        if not fn.state:
            continue
        if fn.model == "template":
            assert fn.name == "friction"
            per_state[fn.name] = [friction_torques(qd, f) for _, qd, _ in states]
        else:
            per_state[fn.name] = [evaluate(programs[fn.name][0], joint_models,
                                           {"q": q, "qd": qd, "qdd": qdd, "s": s, "gravity": gravity,
                                            **({"tau": per_state["rnea"][k]} if "tau" in fn.inputs else {})})
                                  for k, (q, qd, qdd) in enumerate(states)]
    return SelfTestData(p, gravity, f, states, once, per_state)


def selftest_checks(prefix: str, dims: dict, has_gravity: bool) -> list[dict]:
    """What the self-test calls and compares, one entry per catalogue function, in catalogue
    order (the functions of p alone first: their outputs feed the others)."""
    # an argument computed by another function, or a state array standing for another one
    # (the Slotine-Li regressor at qr_d = qd, qr_dd = qdd is the regressor of tau)
    arrays = {"s": "standard_from_dynamic_out", "pi_full": "pi_full_out", "qr_d": "qd", "qr_dd": "qdd",
              "tau": "rnea_out"}

    def size(shape):
        return math.prod(dims[d] for d in shape)

    checks = []
    for fn in sorted(FUNCTIONS, key=lambda fn: fn.state):
        parts, offset = [], 0  # a function with several outputs: each checked against its slice
        for o in fn.outputs if fn.more else ():
            parts.append({"out": f"{fn.name}_{o.name}_out", "offset": offset, "length": size(o.shape),
                          "label": f"{fn.name}.{o.name}"})
            offset += size(o.shape)
        outs = [part["out"] for part in parts] or [f"{fn.name}_out"]
        args = [arrays.get(a, a) for a in fn.arguments(has_gravity)] + outs
        check = {"name": fn.name, "state": fn.state, "out": f"{fn.name}_out",
                 "length": offset or size(fn.output.shape), "parts": parts,
                 "call": f"{prefix}_{fn.name}({', '.join(args)})", "expected": f"{BY_NAME[fn.expected].name}_expected",
                 "label": fn.name, "times": None, "stacked": fn.check.stacked,
                 "own": not fn.check.expected}  # whether its expected values are its own (declared once)
        check["size"] = None
        if fn.check.size:  # |Y| |pi| of that regressor, computed at the same state before this check
            regressor = BY_NAME[fn.check.size]
            rows, cols = (dims[d] for d in regressor.output.shape)
            check["size"] = {"Y": f"{regressor.name}_out", "pi": f"{regressor.check.times}_out", "rows": rows,
                             "cols": cols}
        if fn.check.times:
            rows, cols = (dims[d] for d in fn.output.shape)
            check["times"] = {"out": f"{fn.check.times}_out", "rows": rows, "cols": cols}
            check["label"] = f"{fn.name} * {fn.check.times}"
            check["compared"] = rows
        else:
            check["compared"] = check["length"]
        checks.append(check)
    return checks


def c_numbers(values, per_line: int = 0, indent: int = 8) -> str:
    """Round-trip exact C literals (Python's shortest repr), so the output is deterministic;
    per_line > 0 breaks the list after every per_line numbers (one link, one matrix row)."""
    texts = [repr(float(v)) for v in values]
    if per_line <= 0:
        return ", ".join(texts)
    lines = [", ".join(texts[k:k + per_line]) for k in range(0, len(texts), per_line)]
    return (",\n" + " " * indent).join(lines)
