"""A finding is stable across the fit data, or it is not claimed (diagnosis/stable.py).

The oracle is the injection itself: a sensor gain of GAIN on joint 2 written into the torques
of the effect-free withheld case (MuJoCo, 200 Hz, 20-bit encoder) during the first third of the
fit recording only is an artefact of that stretch; fitted on the whole it is a gain of about a
third of GAIN (claimed at 0.015 before the rule). It must be reported as unstable across blocks,
with the stretches' own values near GAIN, 0 and 0, and not claimed. The same gain over the whole
recording stays a finding, within 20 % (every withheld case keeps its findings:
tests/test_withheld_effects.py). Across recordings the same: with two fit recordings of one arm
(the Fourier excitation and Table V), a gain in one of them only is unstable (a sensor is the
same in both runs), one in both is claimed. With the rule disabled the one-recording gain is
claimed (checked).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from simulation.mujoco_measurements import Encoder
from simulation.withheld_cases import CASES, nominal_model, write_cases

from dyngen.data import condition, read_recording
from dyngen.description import load_robot
from dyngen.diagnosis import diagnose
from dyngen.diagnosis.report_text import markdown, summary_lines
from dyngen.runtime import load

GAIN = 0.08  # relative, on joint 2's torque


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stable")
    write_cases(folder, rate_hz=200.0, cases=[c for c in CASES if c.name == "none"], encoder=Encoder())
    robot = load_robot(ROOT / "examples" / "lwr.yaml")
    return folder, robot, load(ROOT / "generated" / "lwr")


def _diagnosed(case, share: float):
    """The case with joint 2's torque scaled by 1 + GAIN over the first `share` of its fit recording."""
    folder, robot, model = case
    lines = (folder / "none.fit.csv").read_text().splitlines()
    rows = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    t = rows[:, 0]
    rows[t <= t[0] + share * (t[-1] - t[0]), 8 + 1] *= 1 + GAIN  # columns t, q1..q7, tau1..tau7
    path = folder / f"gain-{share:g}.csv"
    path.write_text(lines[0] + "\n" + "\n".join(",".join(repr(float(x)) for x in r) for r in rows) + "\n")
    fit, test = (condition(read_recording(p, robot.dof)) for p in (path, folder / "none.holdout.csv"))
    return diagnose(robot, model, nominal_model(robot), [fit], None, test=[test])


def test_a_gain_in_the_first_third_only_is_flagged_not_claimed(case):
    d = _diagnosed(case, 1 / 3)
    assert not [e for e in d.selected if e.effect == "gain"]
    (u,) = [u for u in d.unstable if u.finding.effect == "gain"]
    assert u.finding.joints == (2,)
    first, *rest = (values[0] for values in u.per_stretch)
    assert abs(first - GAIN) < 0.2 * GAIN
    assert all(abs(v) < 0.1 * GAIN for v in rest)
    assert "Unstable across blocks" in markdown(d, {}) and "gain on joint(s) 2" in markdown(d, {})
    assert any("unstable across blocks" in line and "gain on joint(s) 2" in line for line in summary_lines(d))


def test_the_same_gain_throughout_stays_a_finding(case):
    d = _diagnosed(case, 1.0)
    assert not d.unstable
    (gain,) = [e for e in d.selected if e.effect == "gain"]
    assert gain.joints == (2,) and abs(gain.values["k-1"] - GAIN) < 0.2 * GAIN


def _with_gain(case, name: str, share: float):
    """Recording `name` (none.fit or none.holdout) with joint 2's torque scaled by 1 + GAIN over
    the first `share` of it (0: the recording as written), conditioned."""
    folder, robot, _ = case
    lines = (folder / f"{name}.csv").read_text().splitlines()
    rows = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    t = rows[:, 0]
    rows[t <= t[0] + share * (t[-1] - t[0]), 8 + 1] *= 1 + GAIN  # columns t, q1..q7, tau1..tau7
    path = folder / f"{name}-gain-{share:g}.csv"
    path.write_text(lines[0] + "\n" + "\n".join(",".join(repr(float(x)) for x in r) for r in rows) + "\n")
    return condition(read_recording(path, robot.dof))


def _two_recordings(case, shares):
    """Diagnosed on two fit recordings of the same arm (the Fourier excitation and Table V) with
    the gain over `shares` of each; no test recording (judged on selection blocks)."""
    _, robot, model = case
    fits = [_with_gain(case, name, share) for name, share in zip(("none.fit", "none.holdout"), shares)]
    return diagnose(robot, model, nominal_model(robot), fits, None)


def test_a_gain_in_one_recording_only_is_flagged_not_claimed(case):
    """A gain in the Fourier recording and not in Table V, the same arm: a sensor does not change
    between two runs, so it is no finding (the stretches of each recording are compared)."""
    d = _two_recordings(case, (1.0, 0.0))
    assert not [e for e in d.selected if e.effect == "gain"]
    (u,) = [u for u in d.unstable if u.finding.effect == "gain"]
    assert u.finding.joints == (2,)
    values = [v[0] for v in u.per_stretch]  # 3 stretches of the first recording, then 3 of the second
    assert all(abs(v - GAIN) < 0.2 * GAIN for v in values[:3]), values
    # Table V's rest-to-rest stretches determine the gain less well (one gives -0.035 here)
    assert all(abs(v) < 0.5 * GAIN for v in values[3:]), values


def test_a_gain_in_every_recording_is_claimed(case):
    d = _two_recordings(case, (1.0, 1.0))
    assert not d.unstable
    (gain,) = [e for e in d.selected if e.effect == "gain"]
    assert gain.joints == (2,) and abs(gain.values["k-1"] - GAIN) < 0.2 * GAIN


IA = 0.05  # kg m^2, a rotor inertia on joint 4 (the UR5 trial's wrist: 0.03 true)


def _slowed(traj, after: float, factor: float):
    """traj with its clock slowed to `factor` from `after` on (a cosine ramp of 2 s): the same
    path, accelerations factor^2 as large there, so a rotor inertia is excited in the first part
    only. q(t) = e(w(t)), qd = e' w', qdd = e'' w'^2 + e' w''."""
    fine = np.linspace(traj.t[0], traj.t[-1], 20 * traj.t.size)
    ramp = np.clip((fine - after) / 2.0, 0.0, 1.0)
    speed = 1.0 - (1.0 - factor) * (0.5 - 0.5 * np.cos(np.pi * ramp))
    w = np.concatenate([[fine[0]], fine[0] + np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(fine))])
    change = np.gradient(speed, fine)

    def at(t):
        t = np.asarray(t, dtype=float)
        s, ds, dds = (np.interp(t, fine, v)[:, None] for v in (w, speed, change))
        q, qd, qdd = traj.at(s[:, 0])
        return q, qd * ds, qdd * ds ** 2 + qd * dds

    return type(traj)(traj.t, at)


def test_a_rotor_inertia_excited_in_part_of_the_data_only_stays_claimed(tmp_path):
    """A rotor inertia on joint 4 present throughout, excited in the first third of the fit
    recording only (the motion slowed to 0.3 of its speed after it): the later stretches do not
    determine it and must not vote it unstable; it stays a finding within 20 %."""
    from simulation.mujoco_measurements import Effects
    from simulation.withheld_cases import Case, case_files, trajectories

    robot, model = load_robot(ROOT / "examples" / "lwr.yaml"), load(ROOT / "generated" / "lwr")
    p = nominal_model(robot)
    trajs = trajectories(robot, 200.0)
    trajs["fit"] = _slowed(trajs["fit"], trajs["fit"].t[-1] / 3, 0.3)
    case = Case("rotor", Effects(armature={4: IA}))
    for name, text in case_files(case, 0, robot, p, trajs, 0.05, 0, Encoder()).items():
        (tmp_path / name).write_text(text)
    fit, test = (condition(read_recording(tmp_path / f"rotor.{r}.csv", robot.dof)) for r in ("fit", "holdout"))
    d = diagnose(robot, model, p, [fit], None, test=[test])
    assert not [u for u in d.unstable if u.finding.effect == "armature"], [u.reason for u in d.unstable]
    (ia,) = [e for e in d.selected if e.effect == "armature" and e.joints == (4,)]
    assert abs(ia.values["Ia"] - IA) < 0.2 * IA


def test_two_values_that_are_one_column_on_a_stretch_are_both_undetermined_there():
    """Coulomb friction and an offset on a stretch where the joint moves one way only are one
    column: each has exactly half of itself in the null direction, so `loading < 0.5` let
    rounding pick one of them as determined (with the pseudo-inverse's half-split as its value;
    the 5-min 1 kHz LWR file's joint 5 flipped so with G(q) summed in another order). On a
    stretch (stable.LOADING) neither counts, whatever the rounding; a third, independent value does."""
    from types import SimpleNamespace

    from dyngen.diagnosis.findings import identifiable
    from dyngen.diagnosis.stable import LOADING

    chosen = [SimpleNamespace(slots=np.array([0, 1])), SimpleNamespace(slots=np.array([2]))]
    a = np.array([1.0, 0.3, -0.7, 2.0])
    for e in (0.0, 1e-15, -1e-15, 3e-16):
        A = np.column_stack([a, a * (1 + e), np.array([0.5, -1.0, 1.0, 0.2])])
        determined = identifiable(SimpleNamespace(H=A.T @ A), chosen, LOADING)
        assert determined.tolist() == [False, False, True], (e, determined)


def test_one_stretch_of_nine_outside_the_physical_range_does_not_veto_a_finding(tmp_path):
    """A rotor inertia IA on joint 4 in three fit recordings (the Fourier excitation twice, other
    noise, and Table V: nine stretches) with, on one stretch, the torque of -1.2 IA qdd added: there
    alone the rotor inertia is -0.2 IA, outside its physical range (as where the Panda's wrist stuck
    under sticky friction: bench/trial_other_arm.py). One stretch of nine is not a quarter of them:
    the finding stays claimed, near IA (with the rule that any such stretch vetoes, it was
    "unstable, not claimed"; checked). A physical value that moved still vetoes on any one
    stretch (the gain tests above)."""
    from simulation.mujoco_measurements import Effects
    from simulation.withheld_cases import Case, case_files, trajectories

    from dyngen.diagnosis import stable

    robot, model = load_robot(ROOT / "examples" / "lwr.yaml"), load(ROOT / "generated" / "lwr")
    p = nominal_model(robot)
    trajs = trajectories(robot, 200.0)
    case = Case("rotor", Effects(armature={4: IA}))
    fits = []
    for k in (0, 1):
        (tmp_path / str(k)).mkdir()
        for name, text in case_files(case, k, robot, p, trajs, 0.05, 0, Encoder()).items():
            (tmp_path / str(k) / name).write_text(text)
        fits += [condition(read_recording(tmp_path / str(k) / f"rotor.{r}.csv", robot.dof))
                 for r in (("fit", "holdout") if k == 0 else ("fit",))]
    inner = np.arange(fits[0].trim, fits[0].t.size - fits[0].trim)
    second = np.array_split(inner, stable.STRETCHES)[1]
    fits[0].tau[second, 3] -= 1.2 * IA * fits[0].qdd[second, 3]
    d = diagnose(robot, model, p, fits, None)
    assert not [u for u in d.unstable if u.finding.effect == "armature"], [u.reason for u in d.unstable]
    (ia,) = [e for e in d.selected if e.effect == "armature" and e.joints == (4,)]
    assert abs(ia.values["Ia"] - IA) < 0.25 * IA


def test_an_effect_below_the_floor_is_left_out_of_the_stretches_fits(tmp_path, monkeypatch):
    """A ripple below the significance floor (R sin(3 q6), 0.01 Nm RMS beside 0.05 Nm noise) beside a
    rotor inertia and viscous friction on joint 6 (MuJoCo, 200 Hz, 20-bit encoder, 12 s): the ripple is
    no finding, and the stretches' fits that judge the findings leave it out (stable.unstable's
    `faint`): kept in, its six values took the rotor inertia's share on a 4-s stretch of the Panda
    trial's joint 5 (true 0.05, -0.23 there) and voted the true rotor inertia and viscous friction
    "unstable, not claimed" (bench/trial_other_arm.py --arm panda; not reproduced on this small case,
    where the check is that the faint effect is left out). Both findings stay claimed."""
    import dataclasses

    from simulation.mujoco_measurements import Effects, Trajectory, csv_text, encoded, measure
    from simulation.withheld_cases import grid

    from dyngen.diagnosis import stable

    robot, model = load_robot(ROOT / "examples" / "lwr.yaml"), load(ROOT / "generated" / "lwr")
    p = nominal_model(robot)
    motions = [[(0.4, 0.13)], [(0.3, 0.07)], [(0.3, 0.17)], [(0.3, 0.11)], [(0.4, 0.19)],
               [(0.8, 0.1), (0.3, 0.2), (0.1, 0.5)], [(0.5, 0.29)]]

    def at_of(seed):
        def at(t):
            t = np.atleast_1d(np.asarray(t, float))
            q, qd, qdd = (np.zeros((t.size, 7)) for _ in range(3))
            for j, parts in enumerate(motions):
                for a, f in parts:
                    w = 2 * np.pi * f * (1 + 0.05 * seed)
                    q[:, j] += a * np.sin(w * t)
                    qd[:, j] += a * w * np.cos(w * t)
                    qdd[:, j] -= a * w * w * np.sin(w * t)
            return q, qd, qdd
        return at

    for k, name in enumerate(("fit", "test")):
        m = measure(robot, p, Trajectory(grid(12.0, 200.0), at_of(k)), Effects(armature={6: 0.05}, viscous={6: 0.2}),
                    0.05, seed=[k])
        m = dataclasses.replace(m, tau=m.tau + np.outer(0.012 * np.sin(3 * m.q[:, 5]), np.eye(7)[5]))
        (tmp_path / f"{name}.csv").write_text(csv_text(encoded(m, Encoder(), seed=[k, 1]), velocities=False))
    fit, test = (condition(read_recording(tmp_path / f"{n}.csv", 7)) for n in ("fit", "test"))
    calls, unstable = [], stable.unstable

    def spy(context, segments, design, chosen, x, tau_corr, faint=()):
        calls.append(sorted(chosen[i].key for i in faint))
        return unstable(context, segments, design, chosen, x, tau_corr, faint)

    monkeypatch.setattr(stable, "unstable", spy)
    d = diagnose(robot, model, p, [fit], None, test=[test])
    assert any(x.startswith("ripple on joint 6 (a torque of") for x in d.dropped)
    assert calls[0] == ["ripple on joint 6"]  # (the call without it follows)
    found = {e.effect: e.values for e in d.selected if e.joints == (6,)}
    assert abs(found["armature"]["Ia"] - 0.05) < 0.01 and abs(found["viscous"]["Fv"] - 0.2) < 0.04
