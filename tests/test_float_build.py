"""The float build (<ROBOT>_USE_FLOAT) agrees with the double build on random states.

Tolerance (docs/conventions.md): normwise relative, max_k |f_k - d_k| <= 2e-5 max_k |d_k|,
for every output of every function. Both builds get the same float-representable inputs, so
the difference is the float computation alone. Float's unit roundoff is 2^-24 = 6e-8; the
worst seen on the five example arms is about 2e-6 (35 roundoffs, from the chain of link
transforms and the sums over links), so 2e-5 leaves a factor 10 while a real defect (a wrong
term, a constant printed to float precision twice) is far larger.
"""

from __future__ import annotations

import numpy as np
from oracles.random_params import random_parameters

from dyngen.emission.selftest import TOLERANCE
from dyngen.runtime import load
from dyngen.terms import FRICTION_FIELDS

TOL = TOLERANCE["float"]
assert TOL == 2e-5  # the documented value
N_PARAMETER_SETS, N_STATES = 4, 150


def normwise(single, double) -> float:
    scale = float(np.max(np.abs(double)))
    return float(np.max(np.abs(single.astype(np.float64) - double))) / (scale if scale > 0 else 1.0)


def float_inputs(*arrays):
    return [np.asarray(a, dtype=np.float32).astype(np.float64) for a in arrays]


def test_float_build_agrees_with_double(built, tmp_path_factory):
    single = load(built.c.folder, cache_dir=tmp_path_factory.mktemp("float"), real="float")
    double = built.c
    assert single.dtype == np.float32
    n = built.robot.dof
    n_gravity = len(built.robot.gravity_symbols)
    rng = np.random.default_rng(21)
    worst = {}

    def compare(name, *inputs):
        got, want = single(name, *inputs), double(name, *inputs)
        pairs = zip(got, want) if isinstance(want, tuple) else [(got, want)]  # each output on its own
        err = max(normwise(a, b) for a, b in pairs)
        worst[name] = max(worst.get(name, 0.0), err)

    for _ in range(N_PARAMETER_SETS):
        (p,) = float_inputs(random_parameters(n, seed=rng))
        for name in ("standard_from_dynamic", "pi_gravity", "pi_inertia", "pi_full",
                     "pi_gravity_jacobian", "pi_inertia_jacobian", "pi_full_jacobian"):
            compare(name, p)
        (s,) = float_inputs(single("standard_from_dynamic", p))
        gravity = [9.81 * rng.standard_normal(n_gravity)] if n_gravity else []
        for _ in range(N_STATES):
            q, qd, qdd = float_inputs(rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-5, 5, n))
            g = float_inputs(*gravity)
            compare("rnea", q, qd, qdd, s, *g)
            compare("rnea_nominal", q, qd, qdd, *g)
            compare("gravity", q, s, *g)
            compare("mass_matrix", q, s)
            compare("regressor_gravity", q, *g)
            compare("regressor_inertia", q)
            compare("regressor", q, qd, qdd, *g)
            (pi,) = float_inputs(single("pi_full", p))
            # over the base coefficients the float error is that of the sum Y pi, whose terms can
            # be far larger than tau (a coefficient like m + MY/0.0203 on the PUMA 560): relative
            # to max (|Y| |pi|), the bound of a float dot product
            size = np.abs(double("regressor", q, qd, qdd, *g)) @ np.abs(pi)
            err = float(np.max(np.abs(single("inverse_dynamics", q, qd, qdd, pi, *g).astype(np.float64)
                                      - double("inverse_dynamics", q, qd, qdd, pi, *g)))) / float(np.max(size))
            worst["inverse_dynamics"] = max(worst.get("inverse_dynamics", 0.0), err)
            compare("coriolis_matrix", q, qd, s)
            compare("mass_matrix_derivative", q, qd, s)
            compare("regressor_slotine_li", q, qd, *float_inputs(rng.uniform(-2, 2, n), rng.uniform(-5, 5, n)), *g)
            compare("rnea_derivatives", q, qd, qdd, s, *g)
            (tau,) = float_inputs(double("rnea", q, qd, qdd, s, *g))
            compare("forward_dynamics", q, qd, tau, s, *g)
            compare("forward_dynamics_derivatives", q, qd, tau, s, *g)
            # friction: per joint its terms' fields (terms/friction.py): values and velocity scales
            (f,) = float_inputs(np.column_stack([rng.uniform(0, 2, n) if field.kind == "value" else
                                                 rng.uniform(1e-3, 0.5, n) for field in FRICTION_FIELDS]).ravel())
            compare("friction", qd, f)
            for name in ("link_poses", "flange_pose", "jacobian", "link_jacobians"):
                compare(name, q)
            compare("jacobian_dot_qd", q, qd)
            compare("control", q, qd, s, *g)
            compare("control_with_jacobian", q, qd, s, *g)
    assert len(worst) == len(double.functions)  # every generated function was compared
    assert max(worst.values()) < TOL, {k: f"{v:.1e}" for k, v in worst.items()}
    assert min(worst.values()) > 0  # the float build really computed in float
