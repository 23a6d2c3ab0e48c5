"""`dyngen excite`: the optimised Fourier excitation keeps every limit at every written sample,
starts and ends at rest, is better conditioned than a random trajectory of the same family and
limits, is the same for the same seed, and missing limits are named."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT

from dyngen.description import load_robot
from dyngen.errors import InputError
from dyngen.excitation import Settings, limits_of, optimise
from dyngen.runtime import load

LWR = ROOT / "examples" / "lwr.yaml"
QUICK = dict(max_iterations=3, candidates=3, points=100)


@pytest.fixture(scope="module")
def lwr():
    return load_robot(LWR), load(ROOT / "generated" / "lwr")


def test_limits_rest_and_condition(lwr):
    robot, model = lwr
    design = optimise(robot, model, Settings(seed=3, **QUICK))
    lim = limits_of(robot)
    t = np.arange(0, 10.0 + 1e-9, 1e-3)
    q, qd, qdd = design.trajectory(t)
    assert np.all(q >= lim.lower) and np.all(q <= lim.upper)
    assert np.all(np.abs(qd) <= lim.velocity) and np.all(np.abs(qdd) <= lim.acceleration)
    # at rest at both ends, and back where it started
    for k in (0, -1):
        assert np.max(np.abs(qd[k])) < 1e-9 and np.max(np.abs(qdd[k])) < 1e-9
    assert np.allclose(q[0], q[-1], atol=1e-9)
    # uses the room it has: some joint reaches 90 % of a limit
    assert max(np.max(np.abs(qd) / lim.velocity), np.max(np.abs(qdd) / lim.acceleration)) > 0.9
    assert design.condition < design.random_condition
    same = optimise(robot, model, Settings(seed=3, **QUICK))
    assert np.array_equal(same.trajectory.a, design.trajectory.a) and same.condition == design.condition


def test_missing_acceleration_named(tmp_path, lwr):
    _, model = lwr
    text = LWR.read_text().replace(", acceleration: 6}", "}", 1)
    (tmp_path / "arm.yaml").write_text(text)
    robot = load_robot(tmp_path / "arm.yaml")
    with pytest.raises(InputError, match=r"arm.yaml: joints\[2\].limits.acceleration: missing"):
        optimise(robot, model, Settings(**QUICK))
    bad = LWR.read_text().replace("acceleration: 4}", "acceleration: -4}", 1)
    (tmp_path / "bad.yaml").write_text(bad)
    with pytest.raises(InputError, match=r"bad.yaml: joints\[0\].limits.acceleration: expected a positive number"):
        load_robot(tmp_path / "bad.yaml")


def test_cli_writes_csv_and_plot(tmp_path):
    out = tmp_path / "exc.csv"
    r = subprocess.run([sys.executable, "-m", "dyngen", "excite", LWR, "--model", ROOT / "generated" / "lwr",
                        "--iterations", "3", "--rate", "100", "--period", "5", "-o", out],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "condition number" in r.stdout and "random trajectory with the same limits" in r.stdout
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    header = out.read_text().split("\n", 1)[0].split(",")
    assert header[:2] == ["t", "q1"] and header[-1] == "qdd7" and data.shape == (501, 22)
    assert out.with_suffix(".png").exists()
    r = subprocess.run([sys.executable, "-m", "dyngen", "excite", LWR, "--workspace", "1,0,0,1,0,1", "-o", out],
                       capture_output=True, text=True)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "--workspace" in r.stderr
