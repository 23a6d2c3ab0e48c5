"""The torque terms (dyngen.terms): the emitted friction routine is, by construction, the law
that was fitted. The compiled C of generated/lwr against each term's Python law at random
states for every law alone and every combination; the diagnosis's own columns times its values
against the C fed the friction vector its report writes (Coulomb and Stribeck both selected: the
Stribeck sign keeps its own smoothing, not the Coulomb scale); and one combination against a
law written out here by hand."""

from __future__ import annotations

import itertools
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import ROOT

from dyngen.description import load_robot
from dyngen.diagnosis.record import Finding
from dyngen.diagnosis.updated_model import friction_vector
from dyngen.runtime import load
from dyngen.terms import FRICTION_FIELDS, IN_FRICTION, TERMS, Context, Coulomb, Direction, Stribeck, Viscous, friction_torque

N = 7


@pytest.fixture(scope="module")
def model():
    return load(ROOT / "generated" / "lwr")


def random_fields(rng, chosen, plain: bool):
    """(N, fields): the chosen terms' fields random, the others zero; plain: every other joint's
    velocity scales 0 (the plain sign; no Stribeck term)."""
    f = np.zeros((N, len(FRICTION_FIELDS)))
    k = 0
    for term in IN_FRICTION:
        for field in term.friction:
            if term in chosen:
                scale = rng.uniform(0.005, 0.3, N) if field.kind == "velocity" else rng.uniform(-1.0, 2.0, N)
                if plain and field.kind == "velocity":
                    scale[::2] = 0.0
                f[:, k] = scale
            k += 1
    return f


@pytest.mark.parametrize("plain", [False, True])
@pytest.mark.parametrize("chosen", [c for r in range(1, len(IN_FRICTION) + 1)
                                    for c in itertools.combinations(IN_FRICTION, r)],
                         ids=lambda c: "+".join(t.name for t in c))
def test_emitted_friction_is_the_terms_law(model, chosen, plain):
    rng = np.random.default_rng(len(chosen) + 10 * plain)
    f = random_fields(rng, chosen, plain).ravel()
    for qd in rng.normal(0, 0.3, (20, N)):
        qd[0] = 0.0  # the plain sign's zero
        assert np.allclose(model("friction", qd, f), friction_torque(np, qd, f), rtol=1e-13, atol=1e-15)


def test_friction_vector_of_a_diagnosis_is_the_fitted_law(model):
    """Coulomb at a fitted scale vc with Stribeck, viscous and direction on one joint: the
    friction vector effects.yaml writes, fed to the C, gives the diagnosis's columns @ values."""
    robot = load_robot(ROOT / "examples" / "lwr.yaml")
    sign_velocity = 0.002
    context = Context(model, robot, None, None, sign_velocity)
    chosen = [(Coulomb(0.04), {"Fc": 0.7}), (Stribeck(0.1), {"Fs": 0.3}), (Viscous(), {"Fv": 0.2}),
              (Direction(), {"dFc": 0.05})]
    selected = [Finding(effect=e.name, joints=(3,), variant=e.fixed(), values=v, std={}, units={}, derived={},
                        selection_gain=0.0, rms_before=[], rms_after=[]) for e, v in chosen]
    f = friction_vector(SimpleNamespace(joints=N, selected=selected), sign_velocity)
    rng = np.random.default_rng(3)
    qd = rng.normal(0, 0.2, (50, N))
    fitted = sum(e.columns(context, SimpleNamespace(qd=qd), None)[:, 2, 0] * next(iter(v.values())) for e, v in chosen)
    emitted = np.array([model("friction", x, f)[2] for x in qd])
    assert np.allclose(emitted, fitted, rtol=1e-12, atol=1e-14)
    others = np.array([model("friction", x, f) for x in qd])[:, [0, 1, 3, 4, 5, 6]]
    assert not others.any()  # nothing selected there


def test_one_combination_against_the_law_written_out():
    """An oracle independent of terms/: Fc tanh(v/vc) + Fv v + Fs tanh(v/es) exp(-(v/vs)^2)
    + dFc |tanh(v/ed)|, the fields in the documented order."""
    model = load(ROOT / "generated" / "lwr")
    rng = np.random.default_rng(5)
    Fc, vc, Fv, Fs, vs, es, dFc, ed = (rng.uniform(0.01, 1.0, N) for _ in range(8))
    f = np.column_stack([Fc, vc, Fv, Fs, vs, es, dFc, ed]).ravel()
    assert [x.name for x in FRICTION_FIELDS] == ["Fc", "vc", "Fv", "Fs", "vs", "es", "dFc", "ed"]
    for v in rng.normal(0, 0.5, (10, N)):
        law = Fc * np.tanh(v / vc) + Fv * v + Fs * np.tanh(v / es) * np.exp(-(v / vs) ** 2) + dFc * np.abs(np.tanh(v / ed))
        assert np.allclose(model("friction", v, f), law, rtol=1e-13)


def test_every_term_states_its_values_ranges_and_doc():
    names = [t.name for t in TERMS]
    assert len(set(names)) == len(names) == 13
    for term in TERMS:
        assert term.doc and term.scope in ("joint", "arm")
        for value in term.values:
            assert value.unit and value.low < value.high
    from dyngen.terms import Coulomb as C, Gain, TimeShift
    assert C.inside([0.3]) and not C.inside([-0.1])  # friction opposes motion
    assert Gain.inside([0.2]) and not Gain.inside([0.6])  # a sensor reads 0.5 to 1.5 times the torque
    assert not TimeShift.pointwise and C.pointwise  # a lag needs samples before a chunk


def test_the_diagnosis_candidates_are_the_terms(model):
    """One class per term: every candidate the diagnosis tries is an instance of a term of
    dyngen.terms (its name, values and range the term's own), and no module outside terms/
    defines a second class of one (no Term subclass elsewhere once every stage is imported)."""
    import dyngen.commands.diagnose  # noqa: F401  (every stage that could define one)
    import dyngen.excitation  # noqa: F401
    import dyngen.identification  # noqa: F401
    from dyngen.terms import NAMES, Term, library
    from oracles.random_params import random_parameters

    robot = load_robot(ROOT / "examples" / "lwr.yaml")
    context = Context(model, robot, random_parameters(N, seed=1), None, 0.002)
    candidates = library(context, NAMES)
    assert {c.name for c in candidates} == set(NAMES) == {t.name for t in TERMS}
    for c in candidates:
        term = next(t for t in TERMS if t.name == c.name)
        assert type(c) is term
        assert c.parameters == tuple(v.name for v in term.values) or term.name == "coefficients"

    def subclasses(cls):
        return [s for sub in cls.__subclasses__() for s in (sub, *subclasses(sub))]

    assert len(subclasses(Term)) >= len(TERMS)
    assert all(cls.__module__.startswith("dyngen.terms.") for cls in subclasses(Term)), subclasses(Term)


def test_one_tilt_for_identify_and_diagnose():
    """identify's rotation columns (identification.blocks.tilt_columns) and the diagnosis's Tilt are
    the same term: equal columns at the same estimate, directions u1, u2 = n x u1 (base +x, -y for
    gravity along -z), and the turned gravity vector keeps its size."""
    from oracles.random_params import random_parameters

    from dyngen.identification.blocks import tilt_columns
    from dyngen.terms import Tilt, tilt

    robot = load_robot(ROOT / "examples" / "lwr.yaml")
    p = random_parameters(7, 3, mass=(0.5, 3.0), second_moment=(0.002, 0.02))
    q = np.random.default_rng(8).uniform(-2, 2, (30, 7))
    g = tilt.gravity_of(robot)
    assert np.allclose(tilt.directions(g), [[1, 0, 0], [0, -1, 0], [0, 0, -1]])
    assert tilt.tilt_axes(robot) == ("base +x", "base -y")
    context = Context(None, robot, p, None, 0.002)
    estimate = (0.3, -0.5)
    ours = Tilt.of(context).at(estimate).columns(context, SimpleNamespace(q=q), None)
    assert np.allclose(tilt_columns(g, estimate)(tilt.gravity_matrix(robot, p, q)), ours, rtol=1e-12, atol=1e-12)
    turned = g + tilt.directions(g).T @ tilt.change(g, estimate)
    assert np.linalg.norm(turned) == pytest.approx(np.linalg.norm(g), rel=1e-12)


def test_one_tilt_angle_against_a_turned_gravity():
    """The one tilt-angle formula (terms.tilt.angle_deg, angles_deg) against a base turned by a
    known rotation (Rodrigues, written here): gravity in the turned base frame R^T g gives the
    components a across it, and the angle must be the rotation's, split along the directions it
    turns gravity towards (u1 = base +x, u2 = base -y for gravity along -z). The diagnosis's
    derived angles and its range check use the same formula."""
    from dyngen.terms import Tilt, tilt

    robot = load_robot(ROOT / "examples" / "lwr.yaml")
    g = np.array([0.0, 0.0, -9.81])
    n, u = g / 9.81, np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    rng = np.random.default_rng(21)
    for degrees in (0.5, 3.0, 9.0, 25.0):
        phi = rng.uniform(0, 2 * np.pi)
        k = np.array([np.cos(phi), np.sin(phi), 0.0])  # a horizontal axis
        K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        th = np.radians(degrees)
        R = np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K
        turned = R.T @ g
        a = u @ turned
        # the rotation taking g to `turned`: about g x turned by the angle between them
        omega = np.degrees(np.arccos(turned @ g / (g @ g))) * np.cross(g, turned) / np.linalg.norm(np.cross(g, turned))
        # turning gravity towards u_k is a rotation about n x u_k
        expected = [omega @ np.cross(n, u[0]), omega @ np.cross(n, u[1])]
        assert tilt.angle_deg(g, a) == pytest.approx(degrees, rel=1e-9)
        assert tilt.angles_deg(g, a) == pytest.approx(expected, rel=1e-9, abs=1e-12)
        term = Tilt(9.81, (u[0], u[1]))
        derived = term.derived(robot, {"dg1": a[0], "dg2": a[1]}, {"dg1": 0.0, "dg2": 0.0}, None)
        assert derived["tilt_deg"] == pytest.approx(expected, rel=1e-9, abs=1e-12)
        assert derived["tilt_total_deg"] == pytest.approx(degrees, rel=1e-9)
        assert Tilt.inside(a, {"g": 9.81}) == (degrees < tilt.MAX_TILT_DEG)


def test_one_consistency_check_against_the_pseudo_inertia():
    """The one physical-consistency check of link parameters (parameters.consistency_margin):
    the diagnosis's payload (terms.body.consistent_inertia, standard values) and the extraction's
    links (extraction.problem.is_consistent, dynamic values) against the pseudo-inertia written
    here from the standard values alone, J = [[tr(I_o)/2 E - I_o, m c], [(m c)^T, m]]: a body
    exactly when J is positive semidefinite (random bodies, about half breaking the triangle
    inequality)."""
    from dyngen.extraction.problem import is_consistent
    from dyngen.parameters import dynamic_from_standard_link
    from dyngen.terms.body import consistent_inertia

    rng = np.random.default_rng(5)
    verdicts = []
    for _ in range(400):
        m = rng.uniform(0.1, 5.0)
        h = m * rng.uniform(-0.2, 0.2, 3)
        moments = rng.uniform(0.0, 0.1, 3)
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        c = h / m
        I_o = Q @ np.diag(moments) @ Q.T + m * (c @ c * np.eye(3) - np.outer(c, c))
        standard = np.array([m, *h, I_o[0, 0], I_o[0, 1], I_o[0, 2], I_o[1, 1], I_o[1, 2], I_o[2, 2]])
        J = np.block([[0.5 * np.trace(I_o) * np.eye(3) - I_o, h[:, None]], [h[None, :], np.array([[m]])]])
        smallest = np.linalg.eigvalsh(J)[0]
        if abs(smallest) < 1e-9:
            continue  # on the boundary: rounding decides
        expected = smallest > 0
        assert consistent_inertia(standard) == expected
        assert bool(is_consistent(np.array(dynamic_from_standard_link(standard)))[0]) == expected
        verdicts.append(expected)
    assert 100 < sum(verdicts) < len(verdicts) - 100  # both kinds, many of each


def test_excitation_matrix_is_what_identify_fits(model):
    """The excitation's information matrix times [pi_full(p), per joint Fc, Fv, b and Ia where
    the rigid body does not carry it] is Pinocchio's rnea plus the friction, offset and rotor
    torques written out here; identify's own per-joint columns are the same columns."""
    from oracles.arm import Arm
    from oracles.random_params import random_parameters
    from synthetic import rigid_torques

    from dyngen.excitation import identification_matrix
    from dyngen.identification.columns import joint_column

    rng = np.random.default_rng(12)
    T, v = 25, 0.03
    q, qd, qdd = rng.uniform(-1.5, 1.5, (T, N)), rng.normal(0, 1, (T, N)), rng.normal(0, 2, (T, N))
    p = random_parameters(N, seed=4)
    armature = [j % 2 == 0 for j in range(N)]
    Fc, Fv, b, Ia = (rng.uniform(0.1, 1.0, N) for _ in range(4))
    x = np.concatenate([model("pi_full", p)] + [[Fc[j], Fv[j], b[j]] + ([Ia[j]] if armature[j] else [])
                                                for j in range(N)])
    written = (rigid_torques(Arm.from_yaml(ROOT / "examples" / "lwr.yaml"), p, q, qd, qdd) + Fc * np.tanh(qd / v)
               + Fv * qd + b + Ia * qdd * np.array(armature))
    A = identification_matrix(model, q, qd, qdd, v, armature)
    assert np.allclose(A @ x, written.ravel(), rtol=1e-9, atol=1e-9)
    signals = SimpleNamespace(t=np.arange(T) * 0.01, q=q, qd=qd, qdd=qdd)
    for kind, column in (("viscous", qd), ("offset", np.ones_like(q)), ("armature", qdd), ("ripple_cos", np.cos(q)),
                         ("ripple_sin", np.sin(q))):
        for j in range(N):
            assert np.allclose(joint_column(signals, kind, j), column[:, j], rtol=1e-15), kind
