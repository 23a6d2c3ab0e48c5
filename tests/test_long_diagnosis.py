"""`dyngen diagnose` on a recording longer than --max-rows: read in blocks, diagnosed on evenly
spread windows, the gap and simple model over every sample. Oracles: Pinocchio's torques at
the recorded samples and numpy's least squares (the gap and simple model over the whole file),
the simulated sensor offset (what the diagnosis of the windows must find), and the in-memory
diagnosis (the public function on the whole recording) for a recording within the bound."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np

from dyngen.data import condition, read_recording
from dyngen.diagnosis import diagnose
from dyngen.terms import context
from dyngen.description import load_robot
from dyngen.runtime import load
from oracles.arm import Arm, nominal_parameters
from synthetic import rigid_torques
from test_streaming import FOLDER, LWR, N, ROOT, write_robot

OFFSET = [0, 0, 1.5, 0, 0, 0, 0]  # Nm: the torque sensor's offset on J3


def run(*args):
    out = subprocess.run([sys.executable, "-m", "dyngen", "diagnose", str(LWR), "--params", str(LWR), "--model",
                          str(FOLDER), "-q", *map(str, args)], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    assert out.returncode == 0, out.stderr
    return out


def test_long_recording_diagnosed_on_windows_with_the_gap_over_every_sample(tmp_path):
    path = write_robot(tmp_path / "long.csv", seed=3, seconds=40.0, offset=OFFSET)  # 8000 samples
    run("--data", path, "--max-rows", 3000, "--out", tmp_path / "d")
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    (s,) = doc["sampled"]
    r = read_recording(path, N)
    assert s["rows"] == r.t.size and s["streamed"]
    # windows every 6 * 2^k s, between half the bound and the bound, evenly spread
    starts = [float(name.rpartition("@")[2].rstrip("s")) for name in doc["fit"]]
    assert len(starts) == s["windows"] >= 2 and 1500 < s["rows_diagnosed"] <= 3000
    spacing = np.diff(starts)
    assert np.all(spacing == spacing[0]) and np.log2(spacing[0] / 6.0) % 1 == 0
    # the gap and the simple model over every sample: Pinocchio and numpy
    gap = r.tau - rigid_torques(Arm.from_yaml(LWR), nominal_parameters(LWR), r.q, r.qd, r.qdd)
    assert np.allclose(s["gap_rms"], np.sqrt(np.mean(gap ** 2, axis=0)), rtol=1e-6)
    assert np.allclose(s["gap_mean"], gap.mean(axis=0), atol=1e-6)
    for j in range(N):
        A = np.column_stack([np.ones(r.t.size), np.tanh(r.qd[:, j] / 0.02), r.qd[:, j]])
        x, *_ = np.linalg.lstsq(A, gap[:, j], rcond=None)
        assert np.allclose(s["simple_model"][j], x, rtol=1e-6, atol=1e-8)
        assert np.isclose(s["simple_rms"][j], np.sqrt(np.mean((gap[:, j] - A @ x) ** 2)), rtol=1e-6)
    # the windows' diagnosis finds the sensor's offset
    offset = [e for e in doc["selected"] if e["effect"] == "offset" and e["joints"] == [3]]
    assert offset and abs(offset[0]["values"]["b"] - 1.5) < 0.1
    # chosen alone on J3, its value is set by every row (the final fit reads the file again in blocks):
    # the least squares of a constant, the gap's mean over the whole recording, not over the windows
    assert [e["effect"] for e in doc["selected"] if 3 in e["joints"]] == ["offset"]
    assert abs(offset[0]["values"]["b"] - gap[:, 2].mean()) < 1e-9
    in_windows = np.zeros(r.t.size, dtype=bool)
    for start in starts:
        in_windows |= (r.t - r.t[0] >= start) & (r.t - r.t[0] < start + 6.0)
    assert abs(gap[in_windows, 2].mean() - gap[:, 2].mean()) > 1e-5  # the windows alone would not give it
    assert "## Long recordings: diagnosed on a sample" in (tmp_path / "d" / "report.md").read_text()


def test_recording_within_the_bound_is_the_in_memory_diagnosis(tmp_path, monkeypatch):
    """Also: the memo's bound changes no result (the in-memory run keeps 1 MiB of columns, the
    command 256 MiB)."""
    path = write_robot(tmp_path / "short.csv", seed=4, seconds=5.0, offset=OFFSET)
    run("--data", path, "--out", tmp_path / "d")
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert "sampled" not in doc and doc["fit"] == ["short.csv"]
    assert any(e["effect"] == "offset" and e["joints"] == [3] for e in doc["selected"])
    robot = load_robot(LWR)
    monkeypatch.setattr(context, "MEMO_BYTES", 1 << 20)
    result = diagnose(robot, load(FOLDER), nominal_parameters(LWR), [condition(read_recording(path, N))])
    assert np.allclose(doc["rms_before"], result.rms_before, rtol=1e-9)
    assert np.allclose(doc["rms_after"], result.rms_after, rtol=1e-9)
    assert [e["effect"] for e in doc["selected"]] == [e.effect for e in result.selected]
    for a, b in zip(doc["selected"], result.selected):
        assert a["joints"] == list(b.joints)
        assert np.allclose(list(a["values"].values()), list(b.values.values()), rtol=1e-9)


def test_a_bad_row_deep_in_a_long_recording_is_one_line_and_nothing_written(tmp_path):
    path = write_robot(tmp_path / "long.csv", seed=5, seconds=30.0)
    lines = path.read_text().splitlines()
    lines[5001] = lines[5001].replace(lines[5001].split(",")[3], "nan", 1)  # line 5002, column q3
    path.write_text("\n".join(lines) + "\n")
    out = subprocess.run([sys.executable, "-m", "dyngen", "diagnose", str(LWR), "--params", str(LWR), "--model",
                          str(FOLDER), "--data", str(path), "--max-rows", "1000", "--out", str(tmp_path / "d"), "-q"],
                         capture_output=True, text=True, timeout=300,
                         env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    assert out.returncode != 0
    assert out.stderr.strip().splitlines() == ["dyngen: error: long.csv: line 5002, column q3: nan (NaN or infinite value; missing values are left out only "
                                                 "at the file's start and end)"]
    assert not (tmp_path / "d").exists()


def test_a_control_run_through_the_command(tmp_path):
    """`--control`: the same arm's second run. The sensor offset is in both runs, and an offset is
    the arm's own (not one of across.DIFFERS: gain, payload, gravity scale), so it stays a plain
    finding; a control file that is not there is one line, a non-zero exit and nothing written."""
    path = write_robot(tmp_path / "run.csv", seed=6, seconds=5.0, offset=OFFSET)
    control = write_robot(tmp_path / "control.csv", seed=7, seconds=5.0, offset=OFFSET)
    run("--data", path, "--control", control, "--out", tmp_path / "d")
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    offset = next(e for e in doc["selected"] if e["effect"] == "offset" and e["joints"] == [3])
    assert abs(offset["values"]["b"] - 1.5) < 0.1 and "suspect" not in offset  # an empty suspect is left out
    out = subprocess.run([sys.executable, "-m", "dyngen", "diagnose", str(LWR), "--params", str(LWR), "--model",
                          str(FOLDER), "-q", "--data", str(path), "--control", str(tmp_path / "missing.csv"),
                          "--out", str(tmp_path / "e")], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    assert out.returncode != 0 and len(out.stderr.strip().splitlines()) == 1, out.stderr
    assert "missing.csv" in out.stderr and not (tmp_path / "e").exists()


def test_split_pieces_read_in_blocks_never_mix_roles(tmp_path):
    """--split on a recording over --max-rows: each piece (fit, select, test) read in blocks into
    evenly spread windows of its own time range; within the bound, the pieces are data/split.py's
    cuts of the whole recording, sample for sample."""
    from types import SimpleNamespace

    from dyngen.commands.long_diagnosis import read_split
    from dyngen.data.split import split_recording

    path = write_robot(tmp_path / "long.csv", seed=4, seconds=80.0, offset=OFFSET)  # 16000 samples, 0-80 s
    run("--data", path, "--split", "0.6,0.2,0.2", "--max-rows", 3000, "--out", tmp_path / "d")
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    for role, (a, b) in {"fit": (0, 48), "select": (48, 64), "test": (64, 80)}.items():
        names = doc[role]
        assert len(names) >= 2 and all(n.startswith(f"long.csv [{a / 0.8:.0f}%-{b / 0.8:.0f}%]@") for n in names)
        starts = [float(n.rpartition("@")[2].rstrip("s")) for n in names]  # from the piece's start
        assert all(0 <= s < b - a for s in starts), (role, starts)
    # the test piece (64-80 s, 3200 rows over the bound) judged on its windows, its held-out RMS over every row of it
    r = read_recording(path, N)
    piece = r.t >= r.t[0] + 0.8 * (r.t[-1] - r.t[0])
    gap = (r.tau - rigid_torques(Arm.from_yaml(LWR), nominal_parameters(LWR), r.q, r.qd, r.qdd))[piece]
    assert doc["judged_on"] == "test" and piece.sum() > 3000
    assert np.allclose(doc["rms_before"], np.sqrt(np.mean(gap ** 2, axis=0)), rtol=1e-6)
    args = SimpleNamespace(effort_topic=None, cutoff="auto", order=4, differentiate=False)
    whole = split_recording(read_recording(path, N), (0.6, 0.2, 0.2))
    got = read_split([path], load_robot(LWR), args, (0.6, 0.2, 0.2), 10 ** 6)
    for piece, (signals,) in zip(whole, got):
        assert signals.name == piece.name
        np.testing.assert_array_equal(signals.t, piece.t)
        np.testing.assert_array_equal(signals.tau, piece.tau)


def test_held_out_figures_over_every_row_of_a_long_test_recording(tmp_path):
    """--test longer than --max-rows: the diagnosis judges its windows, but the held-out RMS per
    joint (nominal, the final model, the effects alone, the simple model) is summed block by
    block over every row. Oracles: Pinocchio's torques at every recorded sample with the
    reported values (numpy), and the in-memory diagnosis of the same files (test read whole)."""
    fit = write_robot(tmp_path / "fit.csv", seed=4, seconds=10.0, offset=OFFSET)
    test = write_robot(tmp_path / "test.csv", seed=8, seconds=40.0, offset=OFFSET)  # 8000 samples
    run("--data", fit, "--test", test, "--max-rows", 3000, "--out", tmp_path / "d")
    run("--data", fit, "--test", test, "--out", tmp_path / "whole")  # within the default bound: read whole
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    whole = json.loads((tmp_path / "whole" / "diagnosis.json").read_text())
    assert doc["judged_on"] == "test" and len(doc["test"]) >= 2 and whole["test"] == ["test.csv"]
    r = read_recording(test, N)
    gap = r.tau - rigid_torques(Arm.from_yaml(LWR), nominal_parameters(LWR), r.q, r.qd, r.qdd)
    rms = (lambda x: np.sqrt(np.mean(x ** 2, axis=0)))
    simple = np.array(doc["simple_values"])  # per joint b, Fc, Fv
    simple_torque = simple[:, 0] + simple[:, 1] * np.tanh(r.qd / 0.02) + simple[:, 2] * r.qd
    (offset,) = [e for e in doc["selected"] if e["effect"] == "offset"]
    effects = np.zeros_like(gap)
    effects[:, offset["joints"][0] - 1] = offset["values"]["b"]
    after = np.where([m.startswith("simple") for m in doc["joint_models"]], simple_torque, effects)
    assert [m for m in doc["joint_models"] if m not in ("effects", "simple (effects not shown better)")] == []
    for key, correction in (("before", 0.0), ("after", after), ("effects", effects), ("simple", simple_torque)):
        assert np.allclose(doc[f"rms_{key}"], rms(gap - correction), rtol=1e-6), key
        assert np.allclose(doc[f"rms_{key}"], whole[f"rms_{key}"], rtol=1e-9), key
    # the windows alone would not give it
    in_windows = np.zeros(r.t.size, dtype=bool)
    for name in doc["test"]:
        start = float(name.rpartition("@")[2].rstrip("s"))
        in_windows |= (r.t - r.t[0] >= start) & (r.t - r.t[0] < start + 6.0)
    assert in_windows.sum() <= 3000 and np.abs(rms(gap[in_windows]) / rms(gap) - 1).max() > 1e-3
