"""dyngen.load: the checked-in generated/lwr from Python, one numpy method per function of its
manifest. Every method's outputs are checked against numbers computed without the C: the
values the generator embedded in the manifest (40-digit evaluation of its programs) for the
dynamics, Pinocchio for the kinematics; shapes from the manifest; samples with a leading axis;
the float build; and the errors a user makes."""

from __future__ import annotations

import inspect

import numpy as np
import pytest
from conftest import ROOT
from oracles import kinematics as kin
from oracles.arm import Arm

import dyngen

FOLDER = ROOT / "generated" / "lwr"


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    return dyngen.load(FOLDER)


def test_every_manifest_function_is_a_method_with_its_shapes(model):
    for spec in model.manifest["functions"]:
        short = spec["name"][len("lwr_"):]
        method = getattr(model, short)
        assert list(inspect.signature(method).parameters) == [i["name"] for i in spec["inputs"]]
        assert spec["doc"] in method.__doc__
        args = [np.full(i["length"], 0.25) for i in spec["inputs"]]
        got = method(*args)
        got = got if isinstance(got, tuple) else (got,)
        assert [g.shape for g in got] == [tuple(o["shape"]) for o in spec["outputs"]], short


def test_methods_reproduce_the_embedded_values(model):
    check = model.manifest["selftest"]
    s = model.standard_from_dynamic(check["p"])
    for state in check["states"]:
        q, qd, qdd = state["q"], state["qd"], state["qdd"]
        np.testing.assert_allclose(model.rnea(q, qd, qdd, s), state["tau"], rtol=0, atol=1e-9 * np.abs(state["tau"]).max())
        g, M, c = model.control(q, qd, s)
        np.testing.assert_allclose(g, state["g"], rtol=0, atol=1e-9 * np.abs(state["g"]).max())
        np.testing.assert_allclose(M.ravel(), state["M"], rtol=0, atol=1e-9 * np.abs(state["M"]).max())
        np.testing.assert_allclose(c + g + M @ qdd, state["tau"], rtol=0, atol=1e-9 * np.abs(state["tau"]).max())
        np.testing.assert_allclose(model.friction(qd, check["f"]), state["friction"], rtol=0, atol=1e-12)


def test_kinematics_methods_match_pinocchio(model):
    arm = Arm.from_yaml(ROOT / "examples" / "lwr.yaml")
    tool = kin.tool_matrix(ROOT / "examples" / "lwr.yaml")
    pin_model, data = kin.pinocchio_model(arm, tool)
    rng = np.random.default_rng(2)
    for _ in range(5):
        q, qd = rng.uniform(-3, 3, 7), rng.uniform(-2, 2, 7)
        want = kin.pinocchio_kinematics(pin_model, data, 7, q, qd)
        np.testing.assert_allclose(model.flange_pose(q), want["poses"][-1], rtol=0, atol=1e-12)
        np.testing.assert_allclose(model.jacobian(q=q), want["jacobians"][-1], rtol=0, atol=1e-12)
        np.testing.assert_allclose(model.jacobian_dot_qd(q, qd=qd), want["jdot_qd"], rtol=0, atol=1e-11)


def test_a_leading_sample_axis_runs_every_sample(model):
    rng = np.random.default_rng(4)
    Q, QD = rng.uniform(-2, 2, (6, 7)), rng.uniform(-1, 1, (6, 7))
    s = model.standard_from_dynamic(model.manifest["selftest"]["p"])
    G, M, C = model.control(Q, QD, s)  # s shared by every sample
    assert G.shape == (6, 7) and M.shape == (6, 7, 7) and C.shape == (6, 7)
    for k in range(6):
        g, m, c = model.control(Q[k], QD[k], s)
        assert np.array_equal(G[k], g) and np.array_equal(M[k], m) and np.array_equal(C[k], c)
    assert model.jacobian(Q).shape == (6, 6, 7)


def test_the_float_build(model):
    model32 = dyngen.load(FOLDER, real="float")
    q = np.linspace(-1, 1, 7)
    J32 = model32.jacobian(q)
    assert J32.dtype == np.float32
    assert np.max(np.abs(J32 - model.jacobian(q))) < 2e-5 * np.max(np.abs(model.jacobian(q)))


def test_wrong_calls_say_what_is_expected(model):
    with pytest.raises(ValueError, match="q needs 7 values"):
        model.jacobian(np.zeros(6))
    with pytest.raises(TypeError, match=r"takes \['q', 'qd'\]"):
        model.jacobian_dot_qd(np.zeros(7))
    with pytest.raises(TypeError, match="unexpected"):
        model.jacobian(np.zeros(7), qd=np.zeros(7))
