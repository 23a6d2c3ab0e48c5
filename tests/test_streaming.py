"""Least squares accumulated in blocks, recording by recording, in worker processes or on a Dask
cluster: equal (to rounding) to the in-memory fit of the stacked rows (identification's SVD fit
and numpy's lstsq); the block reader accepts and refuses what the whole-file reader does; with
several robots, the one with a payload is the one that stands out.

Data: Pinocchio torques (tests/synthetic.py) on Fourier trajectories, positions quantised like
an encoder, torque noise."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dyngen.data import Conditioning, condition, read_recording
from dyngen.data.chunks import chunks
from dyngen.data.recording import Recording
from dyngen.errors import InputError
from dyngen.identification import identify
from dyngen.identification.samples import REGRESSOR
from dyngen.runtime import load
from dyngen.streaming.pooled import identify_recordings
from dyngen.streaming.step import Task
from oracles.arm import Arm, nominal_parameters
from synthetic import fourier, noisy, rigid_torques

ROOT = Path(__file__).resolve().parents[1]
LWR = ROOT / "examples" / "lwr.yaml"
FOLDER = ROOT / "generated" / "lwr"
N = 7
ENCODER = 2 * np.pi / 2 ** 20  # a 20-bit encoder step [rad]


def whole(path, dof: int, **kw) -> Recording:
    """The blocks joined: what read_recording returns."""
    pieces = list(chunks(path, dof, **kw))
    first = pieces[0]
    cat = (lambda xs: None if xs[0] is None else np.concatenate(xs))
    return Recording(first.name, cat([p.t for p in pieces]), cat([p.q for p in pieces]),
                     cat([p.tau for p in pieces]), cat([p.qd for p in pieces]), cat([p.qdd for p in pieces]),
                     {k: cat([p.extra[k] for p in pieces]) for k in first.extra})


@pytest.fixture(scope="module")
def model():
    return load(FOLDER)


def write_robot(path, seed, seconds=6.0, payload=None, velocities=True, offset=None):
    """A CSV recording of the LWR on a Fourier trajectory: Pinocchio's torques (+ an optional
    payload, + an optional torque sensor offset per joint), 0.05 Nm noise, positions quantised
    to the encoder step."""
    t, at = fourier(N, seed, duration=seconds, rate=200.0)
    q, qd, qdd = at(t)
    arm = Arm.from_yaml(LWR)
    tau = noisy(rigid_torques(arm, nominal_parameters(LWR), q, qd, qdd, payload), 0.05, seed)
    if offset is not None:
        tau = tau + np.asarray(offset, dtype=float)
    q = np.round(q / ENCODER) * ENCODER
    header = ["t"] + [f"q{j}" for j in range(1, N + 1)]
    columns = [t[:, None], q]
    if velocities:
        header += [f"{p}{j}" for p in ("qd", "qdd") for j in range(1, N + 1)]
        columns += [qd, qdd]
    header += [f"tau{j}" for j in range(1, N + 1)]
    columns.append(tau)
    rows = np.hstack(columns)
    path.write_text(",".join(header) + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")
    return path


def names_of(model, kind):
    return [e["standard"] for e in model.manifest["coefficients"][kind]["expressions"]]


def task(path, kind="full", rows=97, conditioning=Conditioning()):
    return Task(str(path), N, kind, str(FOLDER), conditioning, rows=rows)


def same_estimate(a, b, rtol=1e-7):
    assert a.rows == b.rows and a.unexcited == b.unexcited
    scale = np.max(np.abs(b.values))
    assert np.allclose(a.values, b.values, rtol=rtol, atol=rtol * scale)
    finite = np.isfinite(b.std)
    assert np.array_equal(np.isfinite(a.std), finite)
    assert np.allclose(a.std[finite], b.std[finite], rtol=1e-6)
    for field in ("condition", "scaled_condition", "residual_rms"):
        assert getattr(a, field) == pytest.approx(getattr(b, field), rel=1e-7), field


@pytest.mark.parametrize("kind", ["full", "gravity"])
def test_blocks_equal_the_in_memory_fit(tmp_path, model, kind):
    paths = [write_robot(tmp_path / f"r{k}.csv", seed=k) for k in range(2)]
    streamed = identify_recordings([task(p, kind) for p in paths], names_of(model, kind), workers=1)
    assert all(s.streamed for s in streamed.sums)  # recorded qd, qdd: read in blocks
    signals = [condition(read_recording(p, N)) for p in paths]
    same_estimate(streamed.estimate, identify(model, signals, kind))
    # and numpy's own least squares of the stacked rows (a third computation)
    Y = np.vstack([model.batch(REGRESSOR[kind], *(
        (s.q, s.qd, s.qdd) if kind == "full" else (s.q,))).reshape(-1, len(names_of(model, kind))) for s in signals])
    b = np.concatenate([s.tau.reshape(-1) for s in signals])
    x = np.linalg.lstsq(Y, b, rcond=None)[0]
    assert np.allclose(Y @ streamed.estimate.values, Y @ x, atol=1e-8 * np.abs(b).max())
    if not streamed.estimate.unexcited:  # the textbook deviations and the condition number, by numpy
        sigma2 = np.sum((b - Y @ x) ** 2) / (b.size - Y.shape[1])
        assert np.allclose(streamed.estimate.std, np.sqrt(sigma2 * np.diag(np.linalg.inv(Y.T @ Y))), rtol=1e-5)
        assert streamed.estimate.condition == pytest.approx(np.linalg.cond(Y), rel=1e-6)


def test_repeated_rows_split_across_block_edges_are_left_out_as_in_memory(tmp_path, model):
    """A logger that wrote samples twice: a run of two copies starting at the first row of the
    second block of 97, and a copy that is the last row of a block (whether it counts depends on
    the next block's first row). Read in blocks, the rows are the clean recording's, exactly (the
    oracle: the rows before they were copied), as conditioning the whole file gives them; the
    least squares in blocks is the in-memory fit of the clean recording."""
    from dyngen.identification.blocks import Source

    clean = write_robot(tmp_path / "clean.csv", seed=5)
    lines = clean.read_text().splitlines()
    rows = lines[1:]

    def copy(row, later):  # the same sample, stamped `later` seconds after it when written again
        t, rest = row.split(",", 1)
        return f"{float(t) + later!r},{rest}"

    # data rows 97, 98 repeat row 96 (block 2 begins with them); row 193 (the end of block 2) repeats row 192
    logged = rows[:97] + [copy(rows[96], 1e-3), copy(rows[96], 2e-3)] + rows[97:191] + [copy(rows[190], 2e-3)] + rows[191:]
    assert len(logged) > 3 * 97
    dup = tmp_path / "logged.csv"
    dup.write_text("\n".join([lines[0]] + logged) + "\n")
    truth = read_recording(clean, N)
    source = Source.of_file(dup, N, block_rows=97)
    got = [b for b, *_ in source.blocks()]
    for column in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(np.concatenate([getattr(b, column) for b in got]), getattr(truth, column))
    assert source.rows == truth.t.size and "3 repeated rows" in source.note
    whole_file = condition(read_recording(dup, N))
    np.testing.assert_array_equal(whole_file.q, truth.q)
    assert whole_file.note == source.note
    streamed = identify_recordings([task(dup)], names_of(model, "full"), workers=1)
    assert streamed.sums[0].streamed and streamed.sums[0].samples == truth.t.size
    same_estimate(streamed.estimate, identify(model, [condition(truth)], "full"))


def test_conditioning_of_the_whole_recording_when_blocks_cannot_do_it(tmp_path, model):
    """Positions only: differentiated through the automatic cutoff, over the whole recording."""
    path = write_robot(tmp_path / "q_only.csv", seed=3, velocities=False)
    streamed = identify_recordings([task(path)], names_of(model, "full"), workers=1)
    assert not streamed.sums[0].streamed and "differentiated" in streamed.sums[0].note
    same_estimate(streamed.estimate, identify(model, [condition(read_recording(path, N))], "full"))


def test_block_reader_equals_and_refuses_like_the_whole_file_reader(tmp_path):
    path = write_robot(tmp_path / "r.csv", seed=0, seconds=1.0)
    a, b = read_recording(path, N), whole(path, N, rows=7)
    for field in ("t", "q", "qd", "qdd", "tau"):
        assert np.array_equal(getattr(a, field), getattr(b, field))
    lines = path.read_text().splitlines()
    for k, bad in ((16, lambda x: x.replace(x.split(",")[3], "nan", 1)),  # a NaN in the third block
                   (15, lambda x: "0.0" + x[x.index(","):])):  # time back to 0 at a block's first row
        broken = tmp_path / f"bad{k}.csv"
        changed = list(lines)
        changed[k] = bad(changed[k])
        broken.write_text("\n".join(changed) + "\n")
        with pytest.raises(InputError) as whole_file:
            read_recording(broken, N)
        with pytest.raises(InputError) as blocks:
            list(chunks(broken, N, rows=7))
        assert str(blocks.value) == str(whole_file.value) and f"line {k + 1}" in str(blocks.value)


def test_workers_and_dask_give_the_same_result(tmp_path, model):
    distributed = pytest.importorskip("distributed")
    paths = [write_robot(tmp_path / f"r{k}.csv", seed=k, seconds=3.0) for k in range(3)]
    tasks = [task(p, rows=256) for p in paths]
    names = names_of(model, "full")
    one = identify_recordings(tasks, names, workers=1)
    two = identify_recordings(tasks, names, workers=2)
    with distributed.LocalCluster(n_workers=1, processes=False, threads_per_worker=1, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        on_dask = identify_recordings(tasks, names, scheduler=client)
    for other in (two, on_dask):
        assert [s.name for s in other.sums] == [s.name for s in one.sums]
        same_estimate(other.estimate, one.estimate, rtol=1e-12)
        assert np.allclose(other.rms_pooled, one.rms_pooled, rtol=1e-12)


def test_the_robot_with_a_payload_stands_out(tmp_path, model):
    payload = (3.0, [0.0, 0.0, 0.08], 0.01 * np.eye(3))
    paths = [write_robot(tmp_path / f"robot{k}.csv", seed=k, seconds=10.0, payload=payload if k == 2 else None)
             for k in range(4)]
    result = identify_recordings([task(p, rows=512) for p in paths], names_of(model, "full"), workers=1)
    flagged = dict(result.differs())
    assert list(flagged) == ["robot2.csv"] and flagged["robot2.csv"] == [1, 3]  # J2, J4 carry the payload most
    # each recording's own fit is its own least squares (numpy's lstsq of its rows)
    s = condition(read_recording(paths[2], N))
    Y = model.batch("regressor", s.q, s.qd, s.qdd)
    r = np.column_stack([s.tau[:, j] - Y[:, j, :] @ np.linalg.lstsq(Y.reshape(-1, Y.shape[-1]), s.tau.reshape(-1),
                                                                      rcond=None)[0] for j in range(N)])
    assert np.allclose(result.rms_own[2], np.sqrt(np.mean(r ** 2, axis=0)), rtol=1e-6)


def test_command_with_a_glob(tmp_path):
    for k in range(3):
        write_robot(tmp_path / f"robot{k}.csv", seed=k, seconds=2.0)
    out = tmp_path / "id.yaml"
    run = subprocess.run([sys.executable, "-m", "dyngen", "identify", str(LWR), "--ols", "--data",
                          str(tmp_path / "robot*.csv"), "--model", str(FOLDER), "--workers", "2", "-o", str(out)],
                         capture_output=True, text=True, timeout=300, env={**os.environ, "PYTHONPATH": str(ROOT / "generator")})
    assert run.returncode == 0, run.stderr
    assert "robot0.csv, robot1.csv, robot2.csv" in out.read_text()
    table = out.with_suffix(".recordings.md").read_text()
    assert all(f"robot{k}.csv" in table for k in range(3)) and "differs: none" in table
    bad = subprocess.run([sys.executable, "-m", "dyngen", "identify", str(LWR), "--ols", "--data",
                          str(tmp_path / "nothing*.csv")], capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "no file matches" in bad.stderr


def test_command_on_a_dask_scheduler(tmp_path):
    """`--scheduler ADDRESS`: the command connects to a running cluster (here a local one whose
    worker is a thread of this process) and gets the in-process result."""
    distributed = pytest.importorskip("distributed")
    for k in range(2):
        write_robot(tmp_path / f"robot{k}.csv", seed=k, seconds=2.0)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "generator")}
    base = [sys.executable, "-m", "dyngen", "identify", str(LWR), "--ols", "--data", str(tmp_path / "robot*.csv"),
            "--model", str(FOLDER), "-q"]
    local = subprocess.run([*base, "--workers", "1", "-o", str(tmp_path / "local.yaml")], capture_output=True,
                           text=True, timeout=300, env=env)
    assert local.returncode == 0, local.stderr
    with distributed.LocalCluster(n_workers=1, processes=False, threads_per_worker=1, dashboard_address=None,
                                  protocol="tcp", host="127.0.0.1") as cluster:
        run = subprocess.run([*base, "--scheduler", cluster.scheduler_address, "-o", str(tmp_path / "dask.yaml")],
                             capture_output=True, text=True, timeout=300, env=env)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "dask.yaml").read_text() == (tmp_path / "local.yaml").read_text()
    bad = subprocess.run([*base, "--scheduler", "tcp://127.0.0.1:9", "-o", str(tmp_path / "no.yaml")],
                         capture_output=True, text=True, timeout=300, env=env)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "cannot reach the Dask scheduler" in bad.stderr
    assert not (tmp_path / "no.yaml").exists()


def test_memory_does_not_grow_with_the_length(tmp_path):
    """The per-recording step's peak of traced allocations (NumPy's included) on the real LWR4+
    run tiled to 40 s and to 320 s: the same, since only one block is held at a time."""
    import tracemalloc

    from dyngen.streaming import step

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))  # the benchmark's tiler
    from long_recordings import write

    peaks = []
    for seconds in (40, 320):
        path = tmp_path / f"tiled{seconds}.csv"
        write(path, seconds / 60)
        step.run(task(path, rows=512))  # the model loaded, caches warm
        tracemalloc.start()
        sums = step.run(task(path, rows=512))
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        assert sums.streamed and sums.samples == path.read_text().count("\n") - 1
    data_bytes = 320 * 200 * 29 * 8  # the long recording's values: 15 MB
    assert peaks[1] < 1.2 * peaks[0] + 100_000 and peaks[1] < data_bytes / 3, peaks


def test_block_reader_bounds_like_the_whole_file_reader(tmp_path):
    import gzip

    path = write_robot(tmp_path / "r.csv", seed=1, seconds=0.5)
    packed = tmp_path / "r.csv.gz"
    packed.write_bytes(gzip.compress(path.read_bytes()))
    a, b = read_recording(packed, N), whole(packed, N, rows=9)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.tau, b.tau)
    latin = tmp_path / "latin.csv"
    latin.write_bytes(path.read_bytes().replace(b"\n0.01", b"\n0.01\xe9", 1))
    with pytest.raises(InputError) as whole_file:
        read_recording(latin, N)
    with pytest.raises(InputError) as blocks:
        list(chunks(latin, N, rows=9))
    assert str(blocks.value) == str(whole_file.value) and "latin.csv: line 4: not UTF-8" in str(blocks.value)
    fifo = tmp_path / "fifo.csv"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file"):
        list(chunks(fifo, N))  # refused before opening: opening a FIFO would wait for a writer
    with pytest.raises(InputError, match="not a regular file"):
        list(chunks("/dev/zero", N))
