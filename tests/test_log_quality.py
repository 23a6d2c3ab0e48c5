"""Logs as loggers write them (data/log_quality.py, data/automatic.py, data/trust.py).

A withheld-effect case (tests/simulation/withheld_cases.py: the LWR in MuJoCo, sharp Coulomb
friction on joints 1 and 6, 0.05 Nm torque noise, positions from an encoder, no qd or qdd
columns) is written cleanly and then as loggers write it (tests/simulation/logger.py): 5.5 %
repeated rows, a logger polling on its own jittered clock (repeated rows, dropped samples and
late stamps at once, as the franka_ros logs), 5 % dropped samples, stamps late by up to 0.4
ms, torques updated at a tenth of the rate; at 1 kHz from a 20-bit encoder and at 100 Hz from a
17-bit one (clean, repeated, dropped and polled: stamps up to a period after their samples). Each must give what the clean log gives (the injected effects, within 20 %, test
RMS within 1.5 x the perfect model's: withheld_verdict.problems), and the nominal residual must
stay below the torques. Torques that do not belong to the positions must stop the diagnosis
with exit status 3, one line, report.md and the figure.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT
from simulation import log_variants, logger
from simulation.mujoco_measurements import Encoder
from simulation.withheld_cases import CASES, nominal_model, write_cases
from simulation.withheld_run import run

from dyngen.catalogue import RNEA, STANDARD_FROM_DYNAMIC
from dyngen.data import condition, log_quality, read_recording
from dyngen.data.chunks import chunks
from dyngen.data.log_quality import regular_samples
from dyngen.description import load_robot
from dyngen.data import trust
from dyngen.diagnosis import diagnose
from dyngen.runtime import load

LWR = ROOT / "examples" / "lwr.yaml"
CASE = next(c for c in CASES if c.name == "coulomb")


def _variant(folder, doc, name, out):
    return log_variants.variant(folder, name, out), doc


@pytest.fixture(scope="module")
def arm():
    return load_robot(LWR), load(ROOT / "generated" / "lwr")


@pytest.fixture(scope="module")
def khz(tmp_path_factory):
    out = tmp_path_factory.mktemp("log1k") / "clean"
    return out, write_cases(out, rate_hz=1000.0, cases=[CASE], encoder=Encoder())


@pytest.fixture(scope="module")
def slow(tmp_path_factory):
    out = tmp_path_factory.mktemp("log100") / "clean"
    return out, write_cases(out, rate_hz=100.0, cases=[CASE], encoder=Encoder(noise=5e-5, bits=17))


def _below_the_torques(r, folder, entry, arm) -> bool:
    return log_variants.below_the_torques(r["before"], condition(read_recording(folder / entry["holdout"], arm[0].dof)))


@pytest.mark.parametrize("name", ["clean", *log_variants.PATHOLOGIES])
def test_a_1khz_log_as_loggers_write_it_gives_the_clean_result(arm, khz, tmp_path, name):
    folder, doc = khz if name == "clean" else _variant(*khz, name, tmp_path / name)
    r = run(*arm, folder, doc, CASE.name, "forward")
    assert r["problems"] == [], "\n".join(r["problems"])
    assert _below_the_torques(r, folder, doc["cases"][0], arm)


@pytest.mark.parametrize("name", ["clean", "repeated", "dropped", "polled"])
def test_a_100hz_17bit_log_as_loggers_write_it(arm, slow, tmp_path, name):
    folder, doc = slow if name == "clean" else _variant(*slow, name, tmp_path / name)
    r = run(*arm, folder, doc, CASE.name, "forward")
    assert r["problems"] == [], "\n".join(r["problems"])
    assert _below_the_torques(r, folder, doc["cases"][0], arm)


def test_a_polling_loggers_clock_is_recovered_at_100hz(slow, tmp_path):
    """At 100 Hz the polling logger's stamps are up to a period after the samples they hold (its
    3 ms delays wander over the whole period): the clock is not within JITTER_SHARE of the stamps,
    and the stamps were interpolated onto a 10.6 ms grid. Each row is now the last tick at or
    before its stamp (log_quality._polled): the clean log's clock, its dropped samples filled."""
    folder, _ = slow
    clean = read_recording(folder / "coulomb.holdout.csv", 7)
    path = tmp_path / "polled.csv"
    path.write_text(logger.polled((folder / "coulomb.holdout.csv").read_text(), 3))
    fixed, report = regular_samples(read_recording(path, 7))
    assert report.clock is not None and "late by up to" in report.clock
    n = fixed.t.size  # the logger's last write comes before the last sample
    assert n >= clean.t.size - 2 and np.max(np.abs(fixed.t - clean.t[:n])) < 1e-4
    assert np.max(np.abs(fixed.q - clean.q[:n])) < 2e-3


def test_repeats_and_held_columns_are_found_exactly(khz, tmp_path):
    folder, _ = khz
    clean = read_recording(folder / "coulomb.fit.csv", 7)
    path = tmp_path / "repeated.csv"
    path.write_text(logger.repeated((folder / "coulomb.fit.csv").read_text(), 0.055, 3))
    raw = read_recording(path, 7)
    fixed, report = regular_samples(raw)
    assert raw.t.size - clean.t.size == report.repeated > 0.04 * clean.t.size
    assert np.array_equal(fixed.t, clean.t) and np.array_equal(fixed.tau, clean.tau)
    path.write_text(logger.held((folder / "coulomb.fit.csv").read_text(), "tau", 10))
    held, report = regular_samples(read_recording(path, 7))
    assert report.held == {"tau": 10.0}
    # interpolated between updates, the torque is nearer the clean one than the held steps were
    # (both keep the 0.05 Nm noise of the samples they leave out: 0.067 against 0.100 Nm)
    steps = read_recording(path, 7).tau
    assert np.sqrt(np.mean((held.tau - clean.tau) ** 2)) < 0.8 * np.sqrt(np.mean((steps - clean.tau) ** 2))


def test_rows_copied_with_their_stamp_are_left_out(khz, tmp_path):
    """A logger or an export that writes a message twice, stamp included: the rows were refused
    ("time does not increase", c684f9a); now they are left out at reading, whole or in blocks (a
    copy at a block's edge too), and counted with the repeated rows."""
    folder, _ = khz
    clean = read_recording(folder / "coulomb.fit.csv", 7)
    header, data = logger.parse((folder / "coulomb.fit.csv").read_text())
    twice = np.random.default_rng(5).random(data.shape[0]) < 0.05
    twice[[0, 99, 100]] = True  # the first row; a copy crossing the blocks of 100 rows read below
    path = tmp_path / "copied.csv"
    path.write_text(logger.unparse(header, data[np.repeat(np.arange(data.shape[0]), 1 + twice)]))
    whole = read_recording(path, 7)
    assert whole.copies == twice.sum() and np.array_equal(whole.t, clean.t) and np.array_equal(whole.tau, clean.tau)
    fixed, report = regular_samples(whole)
    assert report.repeated == twice.sum() and any("repeated rows" in n for n in report.notes)
    streamed = log_quality.Streamed()
    blocks = list(streamed.blocks(chunks(path, 7, rows=100)))
    assert np.array_equal(np.concatenate([b.t for b in blocks]), clean.t)
    assert np.array_equal(np.concatenate([b.q for b in blocks]), clean.q)
    assert streamed.report.repeated == twice.sum()


def test_rest_in_a_noise_free_log_is_not_a_repeat(tmp_path):
    """Identical rows while the positions stand still (exact data at rest) are kept."""
    t = np.arange(0, 4, 1e-3)
    q = np.where(t < 2, np.sin(t), np.sin(2.0))[:, None] * np.ones(2)
    tau = 3 * q
    header = "t,q1,q2,tau1,tau2"
    path = tmp_path / "rest.csv"
    path.write_text(logger.unparse(header, np.column_stack([t, q, tau])))
    fixed, report = regular_samples(read_recording(path, 2))
    assert report.repeated == 0 and fixed.t.size == t.size


def test_recorded_accelerations_that_are_noise_are_replaced(arm, khz, tmp_path):
    """qd, qdd recorded as raw differences of the encoder positions: the nominal residual is
    several times the torque on joint 1; the diagnosis differentiates the positions itself."""
    folder, doc = khz
    header, data = logger.parse((folder / "coulomb.fit.csv").read_text())
    t, q, tau = data[:, 0], data[:, 1:8], data[:, 8:15]
    qd = np.gradient(q, t, axis=0)
    names = ["t"] + [f"{k}{i}" for k in ("q", "qd", "qdd", "tau") for i in range(1, 8)]
    path = tmp_path / "raw.csv"
    path.write_text(logger.unparse(",".join(names), np.column_stack([t, q, qd, np.gradient(qd, t, axis=0), tau])))
    robot, model = arm
    d = diagnose(robot, model, nominal_model(robot), [condition(read_recording(path, 7))])
    assert any("conditioned again" in w for w in d.warnings)
    found = {(e.effect, e.joints) for e in d.selected}
    assert {("coulomb", (1,)), ("coulomb", (6,))} <= found


def test_torques_that_do_not_belong_to_the_positions_stop_the_diagnosis(khz, tmp_path):
    folder, _ = khz
    header, data = logger.parse((folder / "coulomb.fit.csv").read_text())
    data[:, 8:15] = data[::-1, 8:15]
    path = tmp_path / "swapped.csv"
    path.write_text(logger.unparse(header, data))
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "dyngen", "diagnose", str(LWR), "--params",
                           str(folder / "params.yaml"), "--data", str(path), "--out", str(out), "-q",
                           "--model", str(ROOT / "generated" / "lwr")], capture_output=True, text=True)
    assert done.returncode == 3, done.stderr
    lines = [x for x in done.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and "cannot support a diagnosis" in lines[0]
    assert "cannot support a diagnosis" in (out / "report.md").read_text()
    assert (out / "conditioning.png").stat().st_size > 1000
    doc = json.loads((out / "diagnosis.json").read_text())
    assert doc["usable"] is False and "selected" not in doc


def test_identify_reports_its_sanity_and_the_simple_model_beside(tmp_path):
    """dyngen identify on the real LWR4+ (fit m1, --select m3): the simple model on the select
    recording is the published figure (docs: 0.755 0.404 0.237 0.411 0.264 0.186 0.259 Nm from
    the paper's parameters), the identified model beats it on every joint (no advice to use
    it), and a Coulomb lag chosen at the end of its grid is named as a bound."""
    here = ROOT / "examples" / "lwr4-real"
    out = tmp_path / "identified.yaml"
    r = subprocess.run([sys.executable, "-m", "dyngen", "identify", str(LWR), "--data", str(here / "measurement_1.csv"),
                        "--select", str(here / "measurement_3.csv"), "--model", str(ROOT / "generated" / "lwr"),
                        "--prior", str(ROOT / "examples" / "lwr_paper_solution.yaml"), "-o", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    text = out.with_suffix(".md").read_text()
    row = next(x for x in text.splitlines() if x.startswith("| simple model"))
    simple = np.array([float(v) for v in row.split("|")[2:-1]])
    assert np.allclose(simple, [0.755, 0.404, 0.237, 0.411, 0.264, 0.186, 0.259], atol=6e-4)
    row = next(x for x in text.splitlines() if x.startswith("| identified"))
    assert np.all(np.array([float(v) for v in row.split("|")[2:-1]]) < simple)
    assert "use the simple model there" not in r.stdout
    assert "last of its search grid" in r.stdout


@pytest.fixture(scope="module")
def exact(tmp_path_factory):
    out = tmp_path_factory.mktemp("exact1k") / "clean"
    return out, write_cases(out, rate_hz=1000.0, cases=[CASE])


def test_a_franka_like_log_with_recorded_velocities(arm, exact, tmp_path):
    """As franka_ros logs: q from a 20-bit encoder (1e-5 rad noise), the controller's qd (1e-3
    rad/s noise), no qdd, 0.05 Nm torque noise, written by a polling logger (repeated rows,
    dropped samples, late stamps). qdd is differentiated from the recorded qd through a cutoff
    chosen from qd's noise (it used to be differentiated unfiltered)."""
    folder, doc = exact
    out = tmp_path / "franka"
    out.mkdir()
    step = 2 * np.pi / 2 ** 20
    for f in folder.iterdir():
        if f.suffix != ".csv":
            shutil.copy(f, out / f.name)
            continue
        header, data = logger.parse(f.read_text())
        names = header.split(",")
        rng = np.random.default_rng(len(f.name))
        keep = [k for k, n in enumerate(names) if not n.startswith("qdd")]
        data[:, 1:8] = np.round((data[:, 1:8] + 1e-5 * rng.standard_normal((data.shape[0], 7))) / step) * step
        data[:, 8:15] += 1e-3 * rng.standard_normal((data.shape[0], 7))
        tau = [k for k, n in enumerate(names) if n.startswith("tau")]
        data[:, tau] += 0.05 * rng.standard_normal((data.shape[0], 7))
        text = logger.unparse(",".join(names[k] for k in keep), data[:, keep])
        (out / f.name).write_text(logger.polled(text, len(f.name)))
    r = run(*arm, out, doc, CASE.name, "forward")
    assert r["problems"] == [], "\n".join(r["problems"])
    assert all(c is not None and c < 20 for c in r["cutoff"])
    assert _below_the_torques(r, out, doc["cases"][0], arm)


def _fine_positions_and_torque_noise(path, bits=24):
    """A clean case file as a robot with fine position sensors writes it: q from a `bits` encoder with 1e-6
    rad noise, no qd or qdd, 0.05 Nm torque noise. Returns (its text, the true t and qdd)."""
    header, data = logger.parse(path.read_text())
    names = header.split(",")
    rng = np.random.default_rng(len(path.name))
    q = [k for k, n in enumerate(names) if n[:1] == "q" and n[1:].isdigit()]
    tau = [k for k, n in enumerate(names) if n.startswith("tau")]
    qdd = [k for k, n in enumerate(names) if n.startswith("qdd")]
    step = 2 * np.pi / 2 ** bits
    out = data.copy()
    out[:, q] = np.round((data[:, q] + 1e-6 * rng.standard_normal((data.shape[0], len(q)))) / step) * step
    out[:, tau] += 0.05 * rng.standard_normal((data.shape[0], len(tau)))
    keep = [0, *q, *tau]
    return logger.unparse(",".join(names[k] for k in keep), out[:, keep]), data[:, 0], data[:, qdd]


@pytest.mark.parametrize("way", ["clock", "rechecked"])
def test_stamps_whose_error_wanders_smoothly(arm, exact, tmp_path, monkeypatch, way):
    """Fine positions (24-bit encoder) stamped when they arrive, the latency wandering smoothly
    (0.5 ms RMS at 20 Hz; 5.5 % of the samples written twice): the position noise, measured over
    the upper band, sees almost nothing and allowed 37 Hz, through which the accelerations were
    3-6 rad/s^2 off (the true ones 0.7-1.6 RMS) and joint 1's nominal residual 10.7 Nm against
    2.7 Nm of torque (main 88a9636). Now the rows are put on the clock that has one sample per row
    (no sample is dropped). Where that clock is not found ("rechecked": it is switched off here),
    the torque check that diagnose and identify run (trust.checked) conditions the log again at
    a lower cutoff. Judged against the simulator's own accelerations through the same filter, and
    the torques."""
    folder, doc = exact
    robot, model = arm
    text, t_true, qdd_true = _fine_positions_and_torque_noise(folder / doc["cases"][0]["fit"])
    path = tmp_path / "wandering.csv"
    path.write_text(logger.wandering(text, seed=1))
    s = model(STANDARD_FROM_DYNAMIC.name, nominal_model(robot))
    if way == "rechecked":
        monkeypatch.setattr(log_quality, "_counted", lambda t, q: (t, None), raising=False)
    sig = condition(read_recording(path, robot.dof))
    if way == "rechecked":
        [sig] = trust.checked(model, s, [sig])
    keep = sig.inner()
    truth = sig.filtered(np.column_stack([np.interp(sig.t, t_true, x) for x in qdd_true.T]))[keep]
    error = np.sqrt(np.mean((sig.qdd[keep] - truth) ** 2, axis=0))
    assert np.all(error < 0.1 * np.sqrt(np.mean(truth ** 2, axis=0))), (error, np.sqrt(np.mean(truth ** 2, axis=0)))
    before = np.sqrt(np.mean((sig.tau[keep] - model.batch(RNEA.name, sig.q[keep], sig.qd[keep], sig.qdd[keep], s)) ** 2,
                             axis=0))
    assert log_variants.below_the_torques(before, sig), (before, np.sqrt(np.mean(sig.tau[keep] ** 2, axis=0)))
    if way == "clock":
        assert "one sample per row" in (sig.log.clock or ""), sig.note
    else:
        assert any("conditioned again" in w for w in sig.warnings), (sig.cutoff, sig.warnings)


@pytest.fixture(scope="module")
def composed(tmp_path_factory):
    out = tmp_path_factory.mktemp("log1k_composed") / "clean"
    case = next(c for c in CASES if c.name == "gain_viscous")
    return out, write_cases(out, rate_hz=1000.0, cases=[case], encoder=Encoder())


@pytest.mark.parametrize("name", ["polled", "repeated"])
def test_a_sensor_gain_beside_friction_fitted_on_table_v_from_a_logger(arm, composed, tmp_path, name):
    """A second case of bench/bench_log_pathologies.py, the other direction: a 5 % gain on joint 2
    beside viscous friction on joint 6, fitted on Table V and tested on the Fourier excitation."""
    folder, doc = _variant(*composed, name, tmp_path / name)
    r = run(*arm, folder, doc, "gain_viscous", "backward")
    assert r["problems"] == [], "\n".join(r["problems"])
    sig = condition(read_recording(folder / doc["cases"][0]["fit"], arm[0].dof))
    assert log_variants.below_the_torques(r["before"], sig)


def test_a_polled_log_that_drops_samples_is_not_one_sample_per_row():
    """Rows of a polling logger, repeats left out: 3 % of the samples dropped, each write stamped up to
    0.95 of a step late. Every row one tick of a clock (the arrival-stamped logger's repair) would put
    the samples up to 0.05 s off here (its drift between drops); the rows keep their stamps, whose
    error stays within a step. Before, the one-sample-per-row clock was taken where its positions
    were smoother than over the jittered stamps (a UR5 trial window: joint 2's test RMS 0.137 -> 0.154)."""
    rng = np.random.default_rng(4)
    period = 0.002
    ticks = np.arange(12000) * period
    kept = np.sort(rng.choice(ticks.size, int(0.97 * ticks.size), replace=False))
    true = ticks[kept]
    q = np.column_stack([np.sin(2 * np.pi * 0.3 * true + j) for j in range(7)])
    stamps = true + rng.uniform(0.0, 0.95 * period, true.size)
    r = log_quality.Recording("polled.csv", stamps, q, np.zeros_like(q))
    fixed, report = regular_samples(r, regrid=False)  # the times as the clock repairs them, not yet a grid
    assert "one sample per row" not in (report.clock or "")
    assert np.max(np.abs(fixed.t - true)) < period
