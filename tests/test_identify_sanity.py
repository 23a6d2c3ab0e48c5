"""Identification sanity through the real `dyngen identify` (identification/sanity.py).

The issue-25 case (tests/simulation/model_error.py): the LWR in MuJoCo with every link's mass
and inertia off by up to 15 %, Coulomb and viscous friction and rotor inertia on every joint
(friction sticks at reversals: a tracking simulation), 500 Hz, 20-bit encoder positions, 0.05
Nm torque noise; the model is the YAML's nominal links. Three trajectories, one per role: fit,
--select, test.

  - On the full 20 s Fourier fit, every value is the simulated one (Coulomb within 5 %, viscous
    10 %, rotor inertia 25 %: joint 7's trades with link 7's own), nothing is flagged (a true
    wrist rotor inertia 10 x the link's own inertia about the joint is inside the physical
    range), and the identified model beats the simple model on every joint of the --select data.
  - On 6 s of the paper's rest-to-rest trajectory, the identified friction of the wrist cannot be
    told from its links; where the simple model predicts the --select data better the result
    takes it, says so, writes it (`simple_model:`), and it predicts a fourth, unseen trajectory
    better there than the identified values would.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT
from simulation import model_error

from dyngen.data import condition, read_recording
from dyngen.description import load_robot
from dyngen.runtime import load
from dyngen.untrusted import read_yaml

LWR = ROOT / "examples" / "lwr.yaml"


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("model_error")
    truth = model_error.write(folder, rate_hz=500.0)
    return folder, truth


def _identify(folder, fit, out):
    r = subprocess.run([sys.executable, "-m", "dyngen", "identify", str(LWR), "--data", str(fit), "--select",
                        str(folder / "select.csv"), "--prior", str(folder / "params.yaml"),
                        "--model", str(ROOT / "generated" / "lwr"), "-o", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout, read_yaml(out), out.with_suffix(".md").read_text()


def _row(text, start):
    row = next(x for x in text.splitlines() if x.startswith(start))
    return np.array([float(v) for v in row.split("|")[2:-1]])


def test_the_issue_case_is_identified_and_nothing_is_flagged(case, tmp_path):
    folder, truth = case
    stdout, doc, table = _identify(folder, folder / "fit.csv", tmp_path / "id.yaml")
    assert "warning" not in stdout, stdout
    friction = doc["friction"]
    for j in range(7):
        assert abs(friction[j]["Fc"] - truth["friction"]["coulomb"][j + 1]) < 0.05 * truth["friction"]["coulomb"][j + 1]
        assert abs(friction[j]["Fv"] - truth["friction"]["viscous"][j + 1]) < 0.1 * truth["friction"]["viscous"][j + 1]
        ia = truth["friction"]["armature"].get(j + 1)
        if ia is not None and friction[j]["Ia"] is not None:  # None: carried by the rigid body
            assert abs(friction[j]["Ia"] - ia) < 0.25 * ia, (j + 1, friction[j]["Ia"], ia)
    assert np.all(_row(table, "| identified") < _row(table, "| simple model"))
    assert "simple_model" not in doc


def _joint_torque(doc, model, sig, j, use_simple):
    """Joint j's torque from the written YAML, evaluated here: the links' rnea plus the friction
    line, or the prior's rnea plus the simple model's three values."""
    def standard(links):
        p = np.array([[link["m"], *link["c"], *link["I"]] for link in links]).ravel()
        return model("standard_from_dynamic", p)

    if use_simple:
        entry = next(e for e in doc["simple_model"]["joints"] if e["joint"] == j + 1)
        rigid = model.batch("rnea", sig.q, sig.qd, sig.qdd, standard(doc["simple_model"]["prior_links"]))[:, j]
        return rigid + entry["b"] + entry["Fc"] * sig.filtered(np.tanh(sig.qd[:, j] / 0.02)) + entry["Fv"] * sig.qd[:, j]
    f = doc["friction"][j]
    assert f["lag"] == 0 and f["ripple"] == [None, None]  # the torque model evaluated here has neither
    rigid = model.batch("rnea", sig.q, sig.qd, sig.qdd, standard(doc["links"]))[:, j]
    return (rigid + f["Fc"] * sig.filtered(np.tanh(sig.qd[:, j] / f["vs"])) + f["Fv"] * sig.qd[:, j]
            + (f["offset"] or 0.0) + (f["Ia"] or 0.0) * sig.qdd[:, j])


def test_a_joint_the_simple_model_predicts_better_gets_it(case, tmp_path):
    folder, _ = case
    lines = (folder / "test.csv").read_text().splitlines(keepends=True)
    short = tmp_path / "short.csv"
    short.write_text("".join(lines[:3001]))  # 6 s of Table V
    stdout, doc, table = _identify(folder, short, tmp_path / "id.yaml")
    assert "predicts the selection data better than the identified model on joint(s)" in stdout
    replaced = [e["joint"] for e in doc["simple_model"]["joints"]]
    assert 6 in replaced
    assert f"Predicted by the simple model (it did better there): {', '.join(f'J{j}' for j in replaced)}." in table
    identified, simple = _row(table, "| identified"), _row(table, "| simple model")
    assert all(simple[j - 1] < identified[j - 1] for j in replaced)
    # on a trajectory no role saw (the 20 s Fourier excitation), joint 6 is predicted better so
    model = load(ROOT / "generated" / "lwr")
    sig = condition(read_recording(folder / "fit.csv", load_robot(LWR).dof))
    keep = sig.inner()
    rms = {k: float(np.sqrt(np.mean((sig.tau[keep, 5] - _joint_torque(doc, model, sig, 5, k)[keep]) ** 2)))
           for k in (True, False)}
    assert rms[True] < 0.7 * rms[False], rms


def test_the_issue_values_are_each_named(case):
    """The issue's joint 7 as identify once reported it on this case, each value put into the
    true model in turn (sanity.ranges on the fit data): a rotor inertia of 0.121 kg m^2 (24 x the
    simulated 0.005), an offset and a ripple (never simulated) of the joint's whole measured
    torque and more, a 40 ms Coulomb lag (the last of its grid), and the prior's weight at the
    last value of its grid are each named; the true values alone are not (nothing is flagged)."""
    from types import SimpleNamespace

    from dyngen.identification.identify_options import LAG_GRID, REGULARISATION_GRID, SMOOTHING_GRID
    from dyngen.identification.sanity import ranges

    folder, truth = case
    robot, model = load_robot(LWR), load(ROOT / "generated" / "lwr")
    fit = [condition(read_recording(folder / "fit.csv", robot.dof))]
    tau7 = float(np.sqrt(np.mean(fit[0].tau[fit[0].inner(), 6] ** 2)))

    def flagged(**change):
        friction = {k: np.array([truth["friction"].get(k, {}).get(j + 1, np.nan) for j in range(7)])
                    for k in ("coulomb", "viscous", "armature", "offset", "ripple_cos", "ripple_sin")}
        lags, regularisation = np.zeros(7), REGULARISATION_GRID[1]
        for key, value in change.items():
            if key == "lag":
                lags[6] = value
            elif key == "regularisation":
                regularisation = value
            else:
                friction[key][6] = value
        c = SimpleNamespace(p=truth["p_true"], friction=friction, lags=lags, smoothing=np.full(7, SMOOTHING_GRID[1]),
                            regularisation=regularisation, selection=[(x, 1.0) for x in REGULARISATION_GRID])
        return ranges(robot, model, c, fit)

    assert flagged() == []
    (line,) = flagged(armature=0.121)
    assert line.startswith("joint 7: rotor inertia 0.121 kg m^2") and "outside its physical range" in line
    (line,) = flagged(offset=1.2 * tau7)
    assert line.startswith("joint 7: offset")
    (line,) = flagged(ripple_cos=tau7, ripple_sin=tau7)
    assert line.startswith("joint 7: position ripple")
    (line,) = flagged(lag=LAG_GRID[-1])
    assert line.startswith("joint 7: the Coulomb lag 40 ms is the last of its search grid")
    (line,) = flagged(regularisation=REGULARISATION_GRID[-1])
    assert "the last of its search grid" in line and "prior" in line


def test_a_heavy_wrist_rotor_is_physical_unless_it_carries_the_torque():
    """A UR-sized wrist (UR5 joint 6: link inertia about the joint 1.3e-4 kg m^2, a harmonic
    drive's reflected rotor inertia 0.03 kg m^2, 230 x; found and flagged by the UR5 trial,
    bench/trial_other_arm.py) is inside the range while friction carries the joint's torque
    (0.045 Nm of 0.5 Nm RMS); the same value making most of a 0.06 Nm torque, or more than the
    torque, is out of it."""
    from dyngen.identification.sanity import rotor_inertia_range

    assert rotor_inertia_range(5, 0.03, 1.3e-4, qdd=1.5, torque=0.5) is None
    assert "outside its physical range" in rotor_inertia_range(5, 0.03, 1.3e-4, qdd=1.5, torque=0.06)
    assert "more than the measured torque" in rotor_inertia_range(5, 0.03, 1.3e-4, qdd=1.5, torque=0.04)
    assert rotor_inertia_range(5, 0.03, 1e-3, qdd=1.5, torque=0.06) is None  # 30 x: a gear's rotor
