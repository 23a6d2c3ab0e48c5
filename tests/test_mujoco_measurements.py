"""The synthetic "measured" data of the withheld-effects benchmark, checked on its own.

MuJoCo without effects equals dyngen's generated rnea; each effect alone adds exactly its
closed-form torque (the payload and the tilt against Pinocchio with the payload merged into
the last link or the gravity turned); the trajectories keep the joint limits; files are
byte-identical for the same seed."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pinocchio as pin
import pytest
from oracles import pinocchio_arm
from oracles.arm import Arm
from simulation.mujoco_measurements import Effects, Trajectory, measure, read_csv, simulator_xml, write_csv
from oracles.random_params import is_consistent, random_parameters
from simulation.withheld_cases import (CASES, PAYLOAD, ROBOT, consistent_nominal, cubic_at, grid, nominal_model, perturbed,
                                    trajectories, write_cases)
from scipy.spatial.transform import Rotation

from dyngen.description import load_robot
from dyngen.validation.excitation import fourier_excitation, robot_excitation
from dyngen.validation.trajectory import TABLE_V_KNOTS, TABLE_V_TIMES, table_v

EXACT = 1e-8  # Nm: MuJoCo's inverse dynamics vs the generated C / Pinocchio


@pytest.fixture(scope="module")
def setup(lwr):
    robot = load_robot(ROBOT)
    p = nominal_model(robot)
    traj = trajectories(robot, rate_hz=500, fit_seconds=3.0)["fit"]
    s = lwr.c("standard_from_dynamic", p)
    q, qd, qdd = traj.states()
    rnea = np.array([lwr.c("rnea", *x, s) for x in zip(q, qd, qdd)])
    return robot, p, traj, rnea


def difference(setup, effects: Effects) -> np.ndarray:
    robot, p, traj, rnea = setup
    return measure(robot, p, traj, effects).tau - rnea


def only(n, columns: dict) -> np.ndarray:
    """A T x n matrix that is zero except the given 1-based columns."""
    T = len(next(iter(columns.values())))
    out = np.zeros((T, n))
    for j, col in columns.items():
        out[:, j - 1] = col
    return out


# ---------------------------------------------------------------- rigid body and each effect alone

def test_rigid_body_equals_generated_rnea(setup, lwr):
    robot, p, _, rnea = setup
    assert np.max(np.abs(rnea)) > 10  # a real test: torques of tens of Nm
    assert np.max(np.abs(difference(setup, Effects()))) < EXACT
    # also on the held-out trajectory (Table V, rest-to-rest cubics), at 20 Hz
    holdout = trajectories(robot, rate_hz=20)["holdout"]
    s = lwr.c("standard_from_dynamic", p)
    expected = np.array([lwr.c("rnea", *x, s) for x in zip(*holdout.states())])
    assert np.max(np.abs(measure(robot, p, holdout).tau - expected)) < EXACT


def test_viscous_armature_offset_and_gain_add_their_closed_form(setup):
    _, _, traj, rnea = setup
    q, qd, qdd = traj.states()
    cases = [
        (Effects(viscous={1: 0.5, 6: 0.3}), only(7, {1: 0.5 * qd[:, 0], 6: 0.3 * qd[:, 5]})),
        (Effects(armature={1: 0.05, 3: 0.02}), only(7, {1: 0.05 * qdd[:, 0], 3: 0.02 * qdd[:, 2]})),
        (Effects(offset={5: 0.8}), only(7, {5: np.full(len(q), 0.8)})),
        (Effects(gain={2: 0.05}), only(7, {2: 0.05 * rnea[:, 1]})),
    ]
    for effects, expected in cases:
        assert np.max(np.abs(expected)) > 0.05  # larger than the noise of the benchmark
        np.testing.assert_allclose(difference(setup, effects), expected, rtol=0, atol=EXACT, err_msg=str(effects))


def test_coulomb_is_sharp_away_from_zero_velocity(setup):
    _, _, traj, _ = setup
    _, qd, _ = traj.states()
    d = difference(setup, Effects(coulomb={1: 1.0, 6: 0.7}))
    expected = only(7, {1: 1.0 * np.sign(qd[:, 0]), 6: 0.7 * np.sign(qd[:, 5])})
    moving = np.abs(qd) > 1e-4
    assert np.all(moving.sum(axis=0) > 0.95 * len(qd))
    np.testing.assert_allclose(d[moving], expected[moving], rtol=0, atol=1e-9)
    assert np.all(np.abs(d[:, [0, 5]]) <= np.array([1.0, 0.7]) + 1e-9)  # never more than Fc, even at rest


def test_coulomb_at_the_rest_knots_of_table_v(setup):
    robot, p, _, _ = setup
    holdout = trajectories(robot, rate_hz=20)["holdout"]
    clean = measure(robot, p, holdout).tau
    m = measure(robot, p, holdout, Effects(coulomb={2: 1.0}))
    d = m.tau[:, 1] - clean[:, 1]
    moving = np.abs(m.qd[:, 1]) > 1e-4
    np.testing.assert_allclose(d[moving], np.sign(m.qd[moving, 1]), atol=1e-9)
    # at the knots (qd = 0) the friction force is bounded by Fc (static friction)
    assert np.all(np.abs(d[~moving]) <= 1.0 + 1e-9) and (~moving).sum() >= len(TABLE_V_TIMES) - 1


def test_stribeck_adds_the_breakaway_excess(setup):
    _, _, traj, _ = setup
    _, qd, _ = traj.states()
    fc, fs, vs = 0.8, 1.6, 0.1
    d = difference(setup, Effects(coulomb={4: fc}, stribeck={4: (fs - fc, vs)}))
    v = qd[:, 3]
    law = np.sign(v) * (fc + (fs - fc) * np.exp(-np.abs(v / vs) ** 2))
    moving = np.abs(v) > 1e-4
    np.testing.assert_allclose(d[moving, 3], law[moving], atol=1e-9)
    assert np.max(np.abs(d[moving, 3]) - fc) > 0.1  # the trajectory does pass through the Stribeck region
    assert np.max(np.abs(np.delete(d, 3, axis=1))) < EXACT


def merged_last_link(p, payload) -> np.ndarray:
    """Link N and a payload (both dynamic parameters in frame N) as one rigid body."""
    P = np.array(p, dtype=float).reshape(-1, 10)
    bodies = [P[-1], np.asarray(payload, dtype=float)]
    m = sum(b[0] for b in bodies)
    c = sum(b[0] * b[1:4] for b in bodies) / m
    inertia = np.zeros((3, 3))
    for b in bodies:
        xx, xy, xz, yy, yz, zz = b[4:]
        d = b[1:4] - c
        inertia += np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]) + b[0] * (d @ d * np.eye(3) - np.outer(d, d))
    P[-1] = [m, *c, inertia[0, 0], inertia[0, 1], inertia[0, 2], inertia[1, 1], inertia[1, 2], inertia[2, 2]]
    return P.ravel()


def pinocchio_torques(arm, p, traj) -> np.ndarray:
    model, data = pinocchio_arm.build(arm, p)
    return np.array([pin.rnea(model, data, *x).copy() for x in zip(*traj.states())])


def test_payload_equals_pinocchio_with_the_payload_merged_into_link_7(setup):
    robot, p, traj, rnea = setup
    tau = measure(robot, p, traj, Effects(payload=PAYLOAD)).tau
    expected = pinocchio_torques(Arm.from_yaml(ROBOT), merged_last_link(p, PAYLOAD), traj)
    assert np.max(np.abs(expected - rnea)) > 1.0  # the payload matters
    np.testing.assert_allclose(tau, expected, rtol=0, atol=EXACT)


def test_payload_sits_at_the_last_dh_frame_on_another_arm():
    """UR5: DH frame 6 is 0.0823 m along the last joint axis (LWR's frame 7 is at its joint)."""
    path = ROBOT.parent / "ur5.yaml"
    robot = load_robot(path)
    p = random_parameters(6, seed=11)
    traj = Trajectory(grid(1.0, 100), robot_excitation(robot, seed=5))
    tau = measure(robot, p, traj, Effects(payload=PAYLOAD)).tau
    np.testing.assert_allclose(tau, pinocchio_torques(Arm.from_yaml(path), merged_last_link(p, PAYLOAD), traj),
                               rtol=0, atol=EXACT)


def test_tilt_equals_pinocchio_with_turned_gravity(setup):
    robot, p, traj, rnea = setup
    axis = np.array([np.cos(0.5), np.sin(0.5), 0.0])
    tau = measure(robot, p, traj, Effects(tilt_deg=3.0, tilt_axis=tuple(axis))).tau
    # the base turned by +3 deg about axis: gravity seen in the base turns by -3 deg
    g = Rotation.from_rotvec(-np.radians(3.0) * axis).apply([0.0, 0.0, -9.81])
    arm = dataclasses.replace(Arm.from_yaml(ROBOT), gravity=g)
    expected = pinocchio_torques(arm, p, traj)
    assert np.max(np.abs(expected - rnea)) > 0.5
    np.testing.assert_allclose(tau, expected, rtol=0, atol=EXACT)


def test_time_shift_delays_the_torque_by_whole_samples():
    robot = load_robot(ROBOT)
    p = nominal_model(robot)
    traj = Trajectory(grid(1.0, 1000), robot_excitation(robot, seed=3))
    clean = measure(robot, p, traj).tau
    shifted = measure(robot, p, traj, Effects(time_shift=0.010)).tau
    np.testing.assert_allclose(shifted[10:], clean[:-10], rtol=0, atol=EXACT)  # 10 ms = 10 samples at 1 kHz
    assert np.max(np.abs(shifted - clean)) > 0.05


def test_noise_has_the_given_sigma_and_the_seed_decides_it(setup):
    robot, p, traj, rnea = setup
    a = measure(robot, p, traj, Effects(), noise=0.05, seed=[0, 1]).tau - rnea
    b = measure(robot, p, traj, Effects(), noise=0.05, seed=[0, 1]).tau - rnea
    c = measure(robot, p, traj, Effects(), noise=0.05, seed=[0, 2]).tau - rnea
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    assert abs(a.std() / 0.05 - 1) < 0.05 and abs(a.mean()) < 4 * 0.05 / np.sqrt(a.size)
    assert np.max(np.abs(np.corrcoef(a.T) - np.eye(7))) < 0.15  # independent joints


def test_bad_effects_are_refused(setup):
    robot, p, _, _ = setup
    for effects, words in [(Effects(coulomb={8: 1.0}), "joint 8"), (Effects(viscous={1: -0.5}), "negative"),
                           (Effects(stribeck={2: (0.5, 0.0)}), "vs > 0"), (Effects(payload=np.ones(9)), "10")]:
        with pytest.raises(ValueError, match=words):
            simulator_xml(robot, p, effects)


# ---------------------------------------------------------------- parameters, trajectories, files

def test_nominal_model_is_the_yaml_with_links_3_and_7_made_consistent():
    robot = load_robot(ROBOT)
    published = np.array([v for link in robot.nominal for v in link.as_tuple()]).reshape(7, 10)
    assert not is_consistent(published[2]) and not is_consistent(published[6])
    fixed = consistent_nominal(published.ravel()).reshape(7, 10)
    assert is_consistent(fixed)
    for i in (0, 1, 3, 4, 5):
        np.testing.assert_array_equal(fixed[i], published[i])
    for i in (2, 6):
        np.testing.assert_array_equal(fixed[i, :4], published[i, :4])  # mass and CoM kept
        e = np.linalg.eigvalsh(np.array(fixed[i, [4, 5, 6, 5, 7, 8, 6, 8, 9]]).reshape(3, 3))
        assert e[0] + e[1] == pytest.approx(1.01 * e[2], rel=1e-12)  # on the boundary of the margin: nearest point
    np.testing.assert_allclose(nominal_model(robot), fixed.ravel(), rtol=1e-9)


def test_coefficient_errors_scale_masses_and_inertias_by_ten_percent():
    p = nominal_model(load_robot(ROBOT))
    P, Q = p.reshape(7, 10), perturbed(p, 0.1, seed=0).reshape(7, 10)
    np.testing.assert_allclose(np.abs(Q[:, 0] / P[:, 0] - 1), 0.1, rtol=1e-12)
    np.testing.assert_array_equal(Q[:, 1:4], P[:, 1:4])
    ratio = Q[:, 4:] / np.where(P[:, 4:] == 0, 1, P[:, 4:])
    for row, p_row in zip(ratio, P[:, 4:]):
        scales = row[p_row != 0]
        assert np.allclose(np.abs(scales - 1), 0.1, rtol=1e-12) and np.ptp(scales) < 1e-12  # one factor per link
    assert is_consistent(Q) and len(set(np.sign(Q[:, 0] - P[:, 0]))) == 2  # both signs occur


def test_excitation_keeps_the_limits_and_its_derivatives_agree():
    robot = load_robot(ROBOT)
    lim = [j.limits for j in robot.joints]
    lower, upper, vel = (np.array([getattr(x, k) for x in lim]) for k in ("lower", "upper", "velocity"))
    excitation = robot_excitation(robot, seed=1)
    t, q, qd, qdd = excitation.sample(20.0, 1000)
    assert t.size == 20001
    assert np.all(q > lower) and np.all(q < upper) and np.all(np.abs(qd) < vel) and np.all(np.abs(qdd) < 5.0)
    # each joint uses its room: some limit is reached to within 15 % (the 0.9 margin)
    use = np.max([np.max(np.abs(qd), axis=0) / vel, np.max(np.abs(qdd), axis=0) / 5.0,
                  np.max(np.abs(q - excitation.offset), axis=0) / np.minimum(upper - excitation.offset,
                                                                             excitation.offset - lower)], axis=0)
    assert np.all(use > 0.85)
    # the derivatives are those of q (central differences, h = 1e-5 s)
    h, ts = 1e-5, t[::97]
    qp, qdp, _ = excitation(ts + h)
    qm, qdm, _ = excitation(ts - h)
    _, qd_s, qdd_s = excitation(ts)
    np.testing.assert_allclose((qp - qm) / (2 * h), qd_s, atol=1e-7)
    np.testing.assert_allclose((qdp - qdm) / (2 * h), qdd_s, atol=1e-7)
    # periodic, deterministic, seed-dependent
    np.testing.assert_allclose(excitation(ts + 10.0)[0], excitation(ts)[0], atol=1e-12)
    np.testing.assert_array_equal(robot_excitation(robot, seed=1)(ts)[0], excitation(ts)[0])
    assert not np.allclose(robot_excitation(robot, seed=2)(ts)[0], excitation(ts)[0])
    with pytest.raises(ValueError, match="velocity"):
        fourier_excitation([-1], [1], [0.0], 5.0, seed=0)


def test_table_v_at_any_time_is_the_papers_trajectory():
    t, q, qd, qdd = table_v(50)
    for got, want in zip(cubic_at(TABLE_V_KNOTS, TABLE_V_TIMES, t), (q, qd, qdd)):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    q0, qd0, qdd0 = cubic_at(TABLE_V_KNOTS, TABLE_V_TIMES, [-0.5, -0.01, 28.5])
    np.testing.assert_array_equal(q0, TABLE_V_KNOTS[[0, 0, -1]])
    assert not np.any(qd0) and not np.any(qdd0)  # at rest before the start and after the end
    robot = load_robot(ROBOT)
    lower = np.array([j.limits.lower for j in robot.joints])
    upper = np.array([j.limits.upper for j in robot.joints])
    vel = np.array([j.limits.velocity for j in robot.joints])
    assert np.all(q >= lower) and np.all(q <= upper) and np.all(np.abs(qd) <= vel)


def test_csv_has_the_header_and_reads_back(setup, tmp_path):
    robot, p, traj, _ = setup
    m = measure(robot, p, traj, Effects(offset={1: 0.3}), noise=0.05, seed=4)
    write_csv(tmp_path / "a.csv", m)
    header = (tmp_path / "a.csv").read_text().split("\n", 1)[0]
    assert header == "t," + ",".join(f"{k}{i}" for k in ("q", "qd", "qdd", "tau") for i in range(1, 8))
    back = read_csv(tmp_path / "a.csv")
    for field in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_allclose(getattr(back, field), getattr(m, field), rtol=1e-11, atol=1e-12)


def test_case_folder_is_deterministic_and_its_truth_complete(tmp_path):
    docs = [write_cases(tmp_path / name, rate_hz=20, fit_seconds=2.0) for name in ("a", "b")]
    names = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "b").iterdir())
    for name in names:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name
    assert json.loads((tmp_path / "a" / "truth.json").read_text()) == docs[0]
    other = write_cases(tmp_path / "c", rate_hz=20, fit_seconds=2.0, seed=1)
    assert (tmp_path / "c" / "none.fit.csv").read_bytes() != (tmp_path / "a" / "none.fit.csv").read_bytes()
    assert other["cases"][0]["name"] == "none"

    doc = docs[0]
    by_name = {c["name"]: c for c in doc["cases"]}
    assert [c.name for c in CASES] == list(by_name)
    assert by_name["none"]["effects"] == []
    seen = {e["effect"] for c in doc["cases"] for e in c["effects"]}
    assert seen == {"coulomb", "viscous", "stribeck", "armature", "offset", "gain", "payload", "tilt", "time_shift",
                    "coefficients"}
    assert sum(len({e["effect"] for e in c["effects"]}) >= 2 for c in doc["cases"]) >= 2  # combined cases
    assert by_name["coulomb"]["effects"] == [{"effect": "coulomb", "joints": [1, 6], "values": {"fc": [1.0, 1.0]}}]
    assert by_name["stribeck"]["effects"][0]["values"] == {"fc": [0.8], "fs": [1.6], "vs": [0.1]}
    tilt = by_name["tilt"]["effects"][0]["values"]
    assert np.degrees(np.arccos(-tilt["gravity"][2] / 9.81)) == pytest.approx(3.0)
    for case in doc["cases"]:
        for kind in ("fit", "holdout"):
            m = read_csv(tmp_path / "a" / case[kind])
            assert m.q.shape == (41 if kind == "fit" else 561, 7)
