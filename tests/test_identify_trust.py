"""`dyngen identify` refuses recordings whose conditioning cannot be trusted (data/trust.py, the
check `dyngen diagnose` makes; docs/measured-data.md, "When conditioning cannot be trusted").

The log: the LWR in MuJoCo with Coulomb friction, 1 kHz, encoder positions (no qd, qdd), as
tests/test_log_quality.py builds it, fitted against examples/lwr.yaml's nominal links.
  - its torques reversed in time (they do not belong to the positions): exit 3, one line naming
    the file, nothing written; so as --select recording, and when read in blocks (--max-rows);
  - as simulated: exit 0, no warning;
  - qd, qdd recorded as raw differences of the encoder positions (recorded accelerations that are
    noise, 11 Nm of nominal residual on joint 1 against 2.7 Nm of torque): conditioned again from
    the positions, with diagnose's warning, exit 0.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT
from simulation import logger
from simulation.mujoco_measurements import Encoder
from simulation.withheld_cases import CASES, write_cases

LWR = ROOT / "examples" / "lwr.yaml"
CASE = next(c for c in CASES if c.name == "coulomb")


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("trust")
    write_cases(folder / "clean", rate_hz=1000.0, cases=[CASE], encoder=Encoder())
    good = folder / "clean" / "coulomb.fit.csv"
    header, data = logger.parse(good.read_text())
    swapped = data.copy()
    swapped[:, 8:15] = data[::-1, 8:15]
    (folder / "swapped.csv").write_text(logger.unparse(header, swapped))
    t, q, tau = data[:, 0], data[:, 1:8], data[:, 8:15]
    qd = np.gradient(q, t, axis=0)
    names = ",".join(["t"] + [f"{k}{i}" for k in ("q", "qd", "qdd", "tau") for i in range(1, 8)])
    (folder / "raw.csv").write_text(logger.unparse(names, np.column_stack([t, q, qd, np.gradient(qd, t, axis=0), tau])))
    (folder / "raw_swapped.csv").write_text(logger.unparse(names, np.column_stack(
        [t, q, qd, np.gradient(qd, t, axis=0), tau[::-1]])))
    return {"good": good, **{k: folder / f"{k}.csv" for k in ("swapped", "raw", "raw_swapped")}}


def identify(out, *args):
    return subprocess.run([sys.executable, "-m", "dyngen", "identify", str(LWR), "--model", str(ROOT / "generated" / "lwr"),
                           "-q", "-o", str(out / "identified.yaml"), *map(str, args)], capture_output=True, text=True)


@pytest.mark.parametrize("how", ["fit", "select", "in blocks"])
def test_torques_that_do_not_belong_to_the_positions_stop_the_identification(logs, tmp_path, how):
    out = tmp_path / "out"
    bad = logs["raw_swapped" if how == "in blocks" else "swapped"]
    args = {"fit": ["--data", bad], "select": ["--data", logs["good"], "--select", bad],
            "in blocks": ["--data", bad, "--max-rows", 1000]}[how]
    done = identify(out, *args)
    assert done.returncode == 3, done.stderr
    lines = [x for x in done.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("dyngen identify: the data cannot support an identification: "
                                                   f"on {bad.name} "), lines
    assert "joint(s) " in lines[0] and " vs " in lines[0] and "diagnosis" not in lines[0]
    assert ("read in blocks" in lines[0]) == (how == "in blocks")
    assert not out.exists()  # nothing written, not even the folder
    assert done.stdout == ""


def test_a_good_log_is_identified_without_a_word(logs, tmp_path):
    done = identify(tmp_path, "--data", logs["good"])
    assert done.returncode == 0, done.stderr
    assert "conditioned again" not in done.stderr and "cannot support" not in done.stderr
    assert "conditioned again" not in (tmp_path / "identified.yaml").read_text()
    assert (tmp_path / "lwr.urdf").is_file() and (tmp_path / "lwr.xml").is_file()


def test_recorded_accelerations_that_are_noise_are_conditioned_again(logs, tmp_path):
    done = identify(tmp_path, "--data", logs["raw"])
    assert done.returncode == 0, done.stderr
    warning = [x for x in done.stderr.splitlines() if "conditioned again" in x]
    assert len(warning) == 1 and warning[0].startswith("warning: raw.csv: the automatic conditioning left a nominal "
                                                       "residual above the measured torque on joint(s) 1"), warning
    assert "positions differentiated" in warning[0]
    assert "conditioned again after the automatic choice failed" in (tmp_path / "identified.yaml").read_text()


@pytest.mark.parametrize("command", ["identify", "diagnose"])
@pytest.mark.parametrize("joint, factor, says", [(3, -1.0, "its sign differs"), (2, 1000.0, "a unit or a gear"),
                                                 (4, 0.01, "a unit or a gear")])
def test_a_torque_of_the_other_sign_or_in_other_units_is_named(logs, tmp_path, command, joint, factor, says):
    """One joint's torque logged with the other sign, in mNm, or as 1/100 of it (a motor-side torque):
    no conditioning repairs it and no effect is a finding, so both commands stop with exit 3 and a line
    that names the joint and the factor. Before, the sign flip got the generic line and the units
    none at all: the diagnosis ran and claimed effects (a 1e3-Nm ripple on the mNm joint)."""
    header, data = logger.parse(logs["good"].read_text())
    data[:, 7 + joint] *= factor
    bad = tmp_path / "convention.csv"
    bad.write_text(logger.unparse(header, data))
    out = tmp_path / "out"
    if command == "identify":
        done = identify(out, "--data", bad)
    else:
        done = subprocess.run([sys.executable, "-m", "dyngen", "diagnose", str(LWR), "--model", str(ROOT / "generated" / "lwr"),
                               "--params", str(LWR), "-q", "--out", str(out), "--data", str(bad)], capture_output=True, text=True)
    assert done.returncode == 3, done.stderr
    lines = [x for x in done.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and f"joint {joint}'s measured torque is {factor:.3g} x the nominal model's ({says}" in lines[0], lines


@pytest.mark.parametrize("reading", ["degrees", "no gravity"])
def test_positions_in_degrees_or_torques_without_gravity_are_named(logs, tmp_path, reading):
    """Positions logged in degrees, or torques with gravity taken out (a gravity-compensated command):
    the nominal residual is far above the torque, and the line says which reading explains it (it was
    the generic "torques that do not belong to the positions")."""
    from dyngen.catalogue import RNEA, STANDARD_FROM_DYNAMIC
    from dyngen.description import load_robot
    from dyngen.runtime import load
    from simulation.withheld_cases import nominal_model

    header, data = logger.parse(logs["good"].read_text())
    if reading == "degrees":
        data[:, 1:8] = np.degrees(data[:, 1:8])
    else:  # the nominal links' gravity: what a controller compensating it with the YAML's model would take out
        model = load(ROOT / "generated" / "lwr")
        s = model(STANDARD_FROM_DYNAMIC.name, nominal_model(load_robot(LWR)))
        zero = np.zeros_like(data[:, 1:8])
        data[:, 8:15] -= model.batch(RNEA.name, data[:, 1:8], zero, zero, s)
    bad = tmp_path / "reading.csv"
    bad.write_text(logger.unparse(header, data))
    done = identify(tmp_path / "out", "--data", bad)
    assert done.returncode == 3, done.stderr
    lines = [x for x in done.stderr.splitlines() if x.strip()]
    says = "its positions are in degrees" if reading == "degrees" else "its torques leave gravity out"
    assert len(lines) == 1 and f"on {bad.name} {says}" in lines[0], lines


def _heavy(folder):
    """The YAML of the LWR's nominal links three times too heavy (every mass and inertia)."""
    from dyngen.data.parameters_file import read_link_parameters

    p = read_link_parameters(LWR, 7).reshape(7, 10)
    heavy = folder / "heavy.yaml"
    heavy.write_text("links:\n" + "".join(f"  - {{m: {3 * float(r[0])!r}, c: [{', '.join(repr(float(x)) for x in r[1:4])}], "
                                          f"I: [{', '.join(repr(3 * float(x)) for x in r[4:])}]}}\n" for r in p))
    return heavy


@pytest.mark.parametrize("command", ["identify", "diagnose"])
def test_link_parameters_far_off_are_told_from_a_broken_log(logs, tmp_path, command):
    """The good log against links three times too heavy (every mass and inertia): the nominal residual is
    above the torque, and the model's torque three times the measured one, as a unit error would give;
    but a rigid-body fit of the data explains them. Identify, whose purpose it is, goes on with a
    warning; diagnose stops, saying to identify first. Before, identify refused the log as untrustworthy."""
    heavy = _heavy(tmp_path)
    out = tmp_path / "out"
    if command == "identify":
        done = identify(out, "--data", logs["good"], "--prior", heavy)
        assert done.returncode == 0, done.stderr
        assert "a rigid-body fit of the data explains it: the conditioning is sound, the link parameters are off" \
            in done.stderr
    else:
        done = subprocess.run([sys.executable, "-m", "dyngen", "diagnose", str(LWR), "--model", str(ROOT / "generated" / "lwr"),
                               "--params", str(heavy), "-q", "--out", str(out), "--data", str(logs["good"])],
                              capture_output=True, text=True)
        assert done.returncode == 3, done.stderr
        assert "the nominal link parameters are far off" in done.stderr and "identify the link parameters first" \
            in done.stderr


def test_every_torque_in_mnm_is_named(logs, tmp_path):
    """Every joint's torque logged in mNm: no joint stands apart from the others, but the arm's common
    factor (1000) is beyond any nominal model's error (0.1..10)."""
    header, data = logger.parse(logs["good"].read_text())
    data[:, 8:15] *= 1000.0
    bad = tmp_path / "mnm.csv"
    bad.write_text(logger.unparse(header, data))
    done = identify(tmp_path / "out", "--data", bad)
    assert done.returncode == 3, done.stderr
    assert "joint 2's measured torque is 1e+03 x the nominal model's (a unit or a gear" in done.stderr


@pytest.mark.parametrize("kind", [["--ols"], ["--kind", "gravity"]])
def test_least_squares_makes_the_same_check(logs, tmp_path, kind):
    """`--ols` and `--kind gravity` (least squares, recordings in blocks) judge each recording on its
    windows as the least squares conditions them: the log whose torques do not belong to its positions
    stops them (exit 3, one line, nothing written), links three times too heavy give the warning and
    the fit, and the good log is fitted without a word. Before, they fitted the first without a word."""
    out = tmp_path / "out"
    done = identify(out, "--data", logs["swapped"], *kind)
    assert done.returncode == 3, done.stderr
    lines = [x for x in done.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("dyngen identify: the data cannot support an identification: "
                                                   "on swapped.csv"), lines
    assert not out.exists() and done.stdout == ""
    done = identify(out, "--data", logs["good"], *kind)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    heavy = _heavy(tmp_path)
    done = identify(tmp_path / "heavy", "--data", logs["good"], "--prior", heavy, *kind)
    assert done.returncode == 0, done.stderr
    assert "the conditioning is sound, the link parameters are off" in done.stderr
    assert (tmp_path / "heavy" / "identified.yaml").is_file()
