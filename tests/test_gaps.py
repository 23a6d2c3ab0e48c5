"""A long gap in a log's stamps (a logger that stopped for seconds: data/log_quality.py LONG_GAP).

Where the positions are differentiated, the recording is made one regular grid for the filter,
and the gap is filled by interpolation; those samples, and the filter's reach either side, are
not data (Signals.inner). The oracle: the same recording cut into two files at the gap, which
invents no sample. A withheld-effect case (tests/simulation/withheld_cases.py: the LWR, Coulomb
friction of 1 Nm on joints 1 and 6, 0.05 Nm torque noise, positions from a 20-bit encoder, no qd
or qdd columns) at 200 Hz with 3 s of rows left out inside the 2-s selection blocks: the
diagnosis must find what it finds on the two files. Before, the 600 interpolated samples were
fitted and selected on as if measured, and neither friction was found (held-out RMS 1.0 and
0.56 Nm on joints 1 and 6 against 0.03 Nm).
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import yaml
from conftest import ROOT
from simulation import logger
from simulation.mujoco_measurements import Encoder
from simulation.withheld_cases import CASES, nominal_model, write_cases
from simulation.withheld_verdict import problems

from dyngen.data import condition, read_recording
from dyngen.description import load_robot
from dyngen.diagnosis import diagnose
from dyngen.diagnosis.report_text import to_json
from dyngen.errors import InputError
from dyngen.runtime import load

CASE = next(c for c in CASES if c.name == "coulomb")
GAP = (7.3, 10.3)  # s: inside the 2-s blocks [6, 8) and [10, 12)


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    out = tmp_path_factory.mktemp("gap200")
    doc = write_cases(out, rate_hz=200.0, cases=[CASE], encoder=Encoder())
    header, data = logger.parse((out / "coulomb.fit.csv").read_text())
    return out, doc, header, data


def _diagnosis(fit_paths, test_path):
    robot, model = load_robot(ROOT / "examples" / "lwr.yaml"), load(ROOT / "generated" / "lwr")
    fit = [condition(read_recording(p, robot.dof)) for p in fit_paths]
    test = condition(read_recording(test_path, robot.dof))
    return json.loads(to_json(diagnose(robot, model, nominal_model(robot), fit, None, test=[test]), {}))


def test_samples_interpolated_in_a_long_gap_are_not_data(case, tmp_path):
    folder, doc, header, data = case
    inside = (data[:, 0] > GAP[0]) & (data[:, 0] < GAP[1])
    gap, before, after = tmp_path / "gap.csv", tmp_path / "before.csv", tmp_path / "after.csv"
    gap.write_text(logger.unparse(header, data[~inside]))
    before.write_text(logger.unparse(header, data[data[:, 0] <= GAP[0]]))
    after.write_text(logger.unparse(header, data[data[:, 0] >= GAP[1]]))
    test = folder / "coulomb.holdout.csv"
    d, cut = _diagnosis([gap], test), _diagnosis([before, after], test)
    # the injected friction found within 20 %, the held-out RMS within 1.5 x the torque noise; as on the two files
    assert problems(doc["cases"][0]["effects"], d, doc["noise_sigma"]) == []
    assert np.allclose(d["rms_after"], cut["rms_after"], rtol=0.02), (d["rms_after"], cut["rms_after"])
    found = {(e["effect"], e["joints"][0]) for e in d["selected"]}
    assert found == {(e["effect"], e["joints"][0]) for e in cut["selected"]} == {("coulomb", 1), ("coulomb", 6)}
    said = [w for w in d["warnings"] if "gap of 3 s in the stamps" in w]
    assert said and "interpolated for the filter only" in said[0] and "not used as data" in said[0], d["warnings"]


def test_a_gap_that_leaves_too_few_samples_is_an_input_error(case, tmp_path):
    _, _, header, data = case
    path = tmp_path / "stalled.csv"
    path.write_text(logger.unparse(header, data[(data[:, 0] < 0.05) | (data[:, 0] > data[-1, 0] - 0.05)]))
    with pytest.raises(InputError, match="long gap.*samples of data"):
        condition(read_recording(path, 7))


def test_identify_leaves_the_gap_out(case, tmp_path):
    """identify (the consistent fit, conditioned signals held whole: identification/blocks.py) on the
    log with the gap: the friction and the residual noise of the two files (before: 2-8 Nm of residual)."""
    _, _, header, data = case
    inside = (data[:, 0] > GAP[0]) & (data[:, 0] < GAP[1])
    (tmp_path / "gap.csv").write_text(logger.unparse(header, data[~inside]))
    res = subprocess.run([sys.executable, "-m", "dyngen", "identify", str(ROOT / "examples" / "lwr.yaml"), "--model",
                          str(ROOT / "generated" / "lwr"), "--data", str(tmp_path / "gap.csv"), "--friction",
                          "coulomb,viscous", "-q", "-o", str(tmp_path / "id.yaml")], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    friction = yaml.safe_load((tmp_path / "id.yaml").read_text())["friction"]
    assert abs(friction[0]["Fc"] - 1.0) < 0.05 and abs(friction[5]["Fc"] - 1.0) < 0.05, friction
    assert max(f["sigma"] for f in friction) < 0.03, friction  # the two files': 0.013-0.018 Nm
