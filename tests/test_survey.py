"""`dyngen diagnose --survey`: the gap of every recording, read in blocks and in parallel, against
an independent oracle (Pinocchio's torques at the recorded samples, numpy's least squares for
the simple model), and the robot whose torque sensor has an offset is the one that stands out."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np

from dyngen.data import read_recording
from oracles.arm import Arm, nominal_parameters
from synthetic import rigid_torques
from test_streaming import FOLDER, LWR, N, ROOT, write_robot

PAPER = ROOT / "examples" / "lwr_paper_solution.yaml"
OFFSET = [0, 0, 1.5, 0, 0, 0, 0]  # Nm on J3 of one robot


def test_survey_against_pinocchio_and_the_odd_robot(tmp_path):
    paths = [write_robot(tmp_path / f"robot{k}.csv", seed=k, seconds=5.0, offset=OFFSET if k == 1 else None)
             for k in range(4)]
    out = tmp_path / "out"
    run = subprocess.run([sys.executable, "-m", "dyngen", "diagnose", str(LWR), "--params", str(LWR), "--survey",
                          "--data", str(tmp_path / "robot*.csv"), "--model", str(FOLDER), "--workers", "2",
                          "--out", str(out)], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    assert run.returncode == 0, run.stderr
    doc = json.loads((out / "recordings.json").read_text())
    assert doc["differs"] == [{"name": "robot1.csv", "joints": [3]}]
    arm, p = Arm.from_yaml(LWR), nominal_parameters(LWR)
    gaps, columns = [], []
    for path, rec in zip(paths, doc["recordings"]):
        r = read_recording(path, N)
        gap = r.tau - rigid_torques(arm, p, r.q, r.qd, r.qdd)  # Pinocchio at the recorded samples
        assert np.allclose(rec["rms"], np.sqrt(np.mean(gap ** 2, axis=0)), rtol=1e-6)
        assert np.allclose(rec["mean"], gap.mean(axis=0), atol=1e-6)
        gaps.append(gap)
        columns.append(np.stack([np.ones_like(r.qd), np.tanh(r.qd / 0.02), r.qd], axis=-1))
    gap, A = np.vstack(gaps), np.vstack(columns)
    for j in range(N):  # the pooled simple model: numpy's least squares of the stacked rows
        x = np.linalg.lstsq(A[:, j, :], gap[:, j], rcond=None)[0]
        assert np.allclose(doc["pooled_simple_model"][j], x, rtol=1e-6, atol=1e-8)
    assert doc["pooled_simple_model"][2][0] > 0.3  # a quarter of the odd robot's offset on J3
    assert "robot1.csv on J3" in (out / "recordings.md").read_text()
