"""Measured data in: CSV checks name file, line and column; conditioning is zero-phase and
differentiates correctly (checked against analytic signals)."""

from __future__ import annotations

import numpy as np
import pytest

from dyngen.data import Conditioning, condition, read_recording
from dyngen.errors import InputError

N = 2


def write(tmp_path, header, rows, name="run.csv"):
    path = tmp_path / name
    path.write_text(",".join(header) + "\n" + "\n".join(",".join(str(v) for v in row) for row in rows) + "\n")
    return path


def good_rows(count=5):
    return [[0.01 * k, 0.1 * k, -0.1 * k, 1.0, 2.0] for k in range(count)]


HEADER = ["t", "q1", "q2", "tau1", "tau2"]


def error_of(path, dof=N, **kw) -> str:
    with pytest.raises(InputError) as err:
        read_recording(path, dof, **kw)
    text = str(err.value)
    assert "\n" not in text
    return text


def test_reads_columns(tmp_path):
    r = read_recording(write(tmp_path, HEADER, good_rows()), N)
    assert r.q.shape == (5, 2) and r.tau.shape == (5, 2) and r.qd is None
    assert np.allclose(r.q[:, 1], -0.1 * np.arange(5))


def test_missing_column(tmp_path):
    text = error_of(write(tmp_path, ["t", "q1", "q2", "tau1"], [r[:4] for r in good_rows()]))
    assert text == "run.csv: line 1 (header): the robot has 2 joints but the file has only tau1..tau1 (missing tau2)"
    text = error_of(write(tmp_path, ["t", "q1", "q2"], [r[:3] for r in good_rows()]))
    assert text == "run.csv: line 1 (header): missing column(s) tau1, tau2"


def test_joint_count_mismatch(tmp_path):
    text = error_of(write(tmp_path, HEADER, good_rows()), dof=1)
    assert text == "run.csv: line 1 (header): the robot has 1 joints but the file has q2"


def test_non_monotonic_time(tmp_path):
    rows = good_rows()
    rows[3][0] = rows[2][0]
    assert error_of(write(tmp_path, HEADER, rows)) == "run.csv: line 5, column t: time does not increase (0.02 after " \
        "0.02); rows with other values share the stamp: was the time written with too few digits?"
    rows[3][0] = 0.015
    assert error_of(write(tmp_path, HEADER, rows)) == "run.csv: line 5, column t: time does not increase (0.015 after 0.02)"


def test_nan_and_text(tmp_path):
    rows = good_rows()
    rows[1][3] = "nan"
    assert error_of(write(tmp_path, HEADER, rows)) == "run.csv: line 3, column tau1: nan (NaN or infinite value; missing values are left out only at the file's start and end)"
    rows[1][3] = "abc"
    assert error_of(write(tmp_path, HEADER, rows)) == 'run.csv: line 3, column tau1: not a number ("abc")'


def test_missing_file_and_no_time(tmp_path):
    assert "cannot read" in error_of(tmp_path / "none.csv")
    assert "no time column t" in error_of(write(tmp_path, ["time", "q1", "q2", "tau1", "tau2"], good_rows()))


def test_filter_is_zero_phase_and_derivatives_are_right(tmp_path):
    """A 0.5 Hz sine through a 4th-order 5 Hz low-pass comes out unshifted and unscaled;
    velocity and acceleration by differentiation match the analytic ones."""
    rate, f = 500.0, 0.5
    t = np.arange(0, 8, 1 / rate)
    w = 2 * np.pi * f
    q = np.column_stack([np.sin(w * t), 0.5 * np.cos(w * t)])
    noise = 1e-3 * np.random.default_rng(0).normal(size=q.shape)
    rows = np.column_stack([t, q + noise, 3 * q + noise])
    path = write(tmp_path, HEADER, rows.tolist())
    s = condition(read_recording(path, N), Conditioning(cutoff=5.0, order=4))
    inner = slice(int(rate), -int(rate))  # away from the ends (filter start-up)
    assert np.max(np.abs(s.q[inner] - q[inner])) < 2e-3
    assert np.max(np.abs(s.tau[inner] - 3 * q[inner])) < 3e-3
    qd = np.column_stack([w * np.cos(w * t), -0.5 * w * np.sin(w * t)])
    assert np.max(np.abs(s.qd[inner] - qd[inner])) < 0.01 * w
    qdd = -w ** 2 * q
    assert np.max(np.abs(s.qdd[inner] - qdd[inner])) < 0.03 * w ** 2


def test_file_velocities_are_used_unless_told(tmp_path):
    header = ["t", "q1", "q2", "qd1", "qd2", "tau1", "tau2"]
    rows = [[0.01 * k, 0.1 * k, 0.0, 7.0, 8.0, 1.0, 2.0] for k in range(20)]
    path = write(tmp_path, header, rows)
    assert np.allclose(condition(read_recording(path, N)).qd, [7.0, 8.0])
    s = condition(read_recording(path, N), Conditioning(differentiate=True))
    assert np.allclose(s.qd[:, 0], 10.0) and np.allclose(s.qd[:, 1], 0.0)


def test_bad_cutoff_names_the_option(tmp_path):
    path = write(tmp_path, HEADER, good_rows(50))
    with pytest.raises(InputError, match="cutoff: 80 Hz must lie between 0 and half the sampling rate"):
        condition(read_recording(path, N), Conditioning(cutoff=80.0))


@pytest.mark.parametrize("rate", [200.0, 500.0, 1000.0])
def test_automatic_conditioning_of_encoder_positions(tmp_path, rate):
    """Positions from a 20-bit encoder with 1e-5 rad noise, no velocity columns: the cutoff is
    chosen from the recording, and the accelerations come out within 2 % of the motion's
    (central differences of the raw positions would be noisy by tens of rad/s^2 here)."""
    t = np.arange(0, 20, 1 / rate)
    w = 2 * np.pi * np.array([0.1, 0.3, 0.5])
    q = np.column_stack([0.8 * np.sin(w[0] * t) + 0.2 * np.sin(w[2] * t + 1), 0.5 * np.cos(w[1] * t)])
    qdd = np.column_stack([-0.8 * w[0] ** 2 * np.sin(w[0] * t) - 0.2 * w[2] ** 2 * np.sin(w[2] * t + 1),
                           -0.5 * w[1] ** 2 * np.cos(w[1] * t)])
    step = 2 * np.pi / 2 ** 20
    measured = np.round((q + 1e-5 * np.random.default_rng(1).standard_normal(q.shape)) / step) * step
    path = write(tmp_path, HEADER, np.column_stack([t, measured, q]).tolist())
    s = condition(read_recording(path, N))
    assert 2.0 < s.cutoff < 0.2 * rate and s.trim > 0 and "chosen from the data" in s.note
    inner = s.inner()
    error = np.sqrt(np.mean((s.qdd[inner] - qdd[inner]) ** 2))
    assert error < 0.02 * np.sqrt(np.mean(qdd ** 2))
    raw = np.gradient(np.gradient(measured, t, axis=0), t, axis=0)
    assert np.sqrt(np.mean((raw - qdd) ** 2)) > 50 * error
    assert condition(read_recording(path, N), Conditioning(cutoff=3.0)).cutoff == 3.0  # the override


def _stamped(tmp_path, stamps, clock, name):
    """Positions of a smooth motion sampled on `clock`, written with the times `stamps`."""
    w = 2 * np.pi * 0.4
    q = np.column_stack([np.sin(w * clock), 0.5 * np.cos(1.3 * w * clock)])
    rows = np.column_stack([stamps, q, q])
    return write(tmp_path, HEADER, [[f"{v:.12g}" for v in row] for row in rows], name), w


@pytest.mark.parametrize("dropped", [False, True])
def test_jittering_stamps_give_way_to_the_clock(tmp_path, dropped):
    """A logger that stamps samples late (pairs of +1.5 ms, as the real LWR4+ recordings):
    the accelerations over the stamps carry spikes, over the recovered clock they match the
    analytic ones; a dropped sample stays a gap of two periods."""
    rate = 200.0
    clock = np.arange(0, 12, 1 / rate)
    if dropped:
        clock = np.delete(clock, 1000)
    stamps = clock.copy()
    late = np.random.default_rng(1).choice(np.arange(10, clock.size - 10), 40, replace=False)
    stamps[late] += 0.0015
    path, w = _stamped(tmp_path, stamps, clock, "jitter.csv")
    s = condition(read_recording(path, N), Conditioning(cutoff=None, differentiate=True))
    assert np.max(np.abs(s.t - clock)) < 1e-9
    assert any("jitter" in x for x in s.warnings) and "clock" in s.note
    inner = slice(5, -5)
    analytic = -w ** 2 * np.sin(w * clock)
    assert np.max(np.abs(s.qdd[inner, 0] - analytic[inner])) < 0.01 * w ** 2
    # what differentiating over the stamps would have given: the case is not trivial
    over_stamps = np.gradient(np.gradient(np.sin(w * clock), stamps), stamps)
    assert np.max(np.abs(over_stamps[inner] - analytic[inner])) > 10 * w ** 2


def test_exact_or_truly_irregular_stamps_are_kept(tmp_path):
    """Stamps that are the sampling times (regular, or irregular but where the positions were
    really taken) are left alone: over them the motion is already smooth."""
    rng = np.random.default_rng(2)
    regular = np.arange(0, 10, 1 / 500.0)
    irregular = np.cumsum(rng.uniform(0.0035, 0.0065, 2000))
    for name, t in (("regular.csv", regular), ("irregular.csv", irregular)):
        path, _ = _stamped(tmp_path, t, t, name)
        s = condition(read_recording(path, N), Conditioning(cutoff=None, differentiate=True))
        assert np.array_equal(s.t, read_recording(path, N).t), name
        assert not any("jitter" in x for x in s.warnings), name


@pytest.mark.parametrize("unit, scale, origin", [("ms", 1e3, 0.0), ("us", 1e6, 0.0), ("ns", 1e9, 0.0),
                                                 ("s", 1.0, 1.765e9), ("ns", 1e9, 1.765e18)])
def test_stamps_in_other_units_or_from_an_absolute_clock(tmp_path, unit, scale, origin):
    """A 1 kHz log stamped in ms, us or ns, or by Unix time (seconds, or nanoseconds as ROS writes
    them): read as seconds from the first row, whole and in blocks, and said. A log in ms was read
    as a 1 Hz log and diagnosed without a word; Unix time was refused ("value out of range")."""
    from dyngen.data.chunks import chunks

    t = 0.001 * np.arange(300) + 0.0001 * np.sin(np.arange(300))  # jittered, as a logger's clock
    rows = [[float(origin + scale * tk), float(np.sin(tk)), float(np.cos(tk)), 1.0, 2.0] for tk in t]
    path = tmp_path / "run.csv"
    path.write_text(",".join(HEADER) + "\n" + "\n".join(",".join(repr(v) for v in row) for row in rows) + "\n")
    whole = read_recording(path, N)
    blocks = list(chunks(path, N, rows=64))
    precision = 3e-7 if origin else 1e-9  # float64 spacing of Unix time: 238 ns in s, 256 ns in ns
    for got in (whole.t, np.concatenate([b.t for b in blocks])):
        assert np.max(np.abs(got - (t - t[0] * (origin > 0)))) < precision
    said = whole.read_note or ""
    assert (f"t read in {unit}" in said) == (unit != "s") and ("absolute clock" in said) == (origin > 0)
    assert said.split(": its")[0] == (blocks[0].read_note or "").split(": its")[0]  # the median of one block or all
    assert "t read in" in (condition(whole).note if unit != "s" else "t read in")


def test_a_time_column_beyond_any_clock_is_refused(tmp_path):
    rows = good_rows()
    rows[2][0] = 2e19
    assert error_of(write(tmp_path, HEADER, rows)) == "run.csv: line 4, column t: 2e+19: value out of range (|x| at most 1e+19)"


@pytest.mark.parametrize("sep", [";", "\t", " "])
def test_a_file_separated_otherwise_is_named(tmp_path, sep):
    path = tmp_path / "run.csv"
    path.write_text(sep.join(HEADER) + "\n" + "\n".join(sep.join(str(v) for v in row) for row in good_rows()) + "\n")
    assert f"the values are separated by {sep!r}, not commas" in error_of(path)


@pytest.mark.parametrize("joint, factor", [(2, 180 / np.pi), (5, -1.0), (6, 100.0)])
def test_recorded_velocities_in_another_unit_are_set_aside(tmp_path, joint, factor):
    """The real LWR4+ log (examples/lwr4-real, qd and qdd recorded by the controller) with one joint's
    qd, qdd in deg/s, of the other sign, or motor-side (x 100): the positions are differentiated
    instead, and said; as logged, the recorded columns are used (they agree with the positions)."""
    from conftest import ROOT

    source = ROOT / "examples" / "lwr4-real" / "measurement_1.csv"
    header, *lines = source.read_text().splitlines()
    names = header.split(",")
    data = np.array([[float(x) for x in line.split(",")] for line in lines])
    assert condition(read_recording(source, 7)).note.endswith("qd, qdd as recorded, no filter")
    data[:, [names.index(f"qd{joint}"), names.index(f"qdd{joint}")]] *= factor
    path = tmp_path / "other_unit.csv"
    path.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in data) + "\n")
    sig = condition(read_recording(path, 7))
    again = condition(read_recording(path, 7), Conditioning(differentiate=True))
    assert f"x the positions' derivative on joint {joint} " in sig.warnings[0], sig.warnings
    said = float(sig.warnings[0].split("recorded qd is ")[1].split(" x")[0])
    assert abs(said / factor - 1) < 0.01 and np.array_equal(sig.qdd, again.qdd)


def test_rows_missing_values_at_the_ends_are_left_out(tmp_path):
    """A logger that merges topics writes rows before every column has a value, and after one stops:
    empty cells or NaN at the file's start and end are left out and said (they were refused); between
    complete rows a missing value is still named with its line. In blocks, only the start's."""
    from dyngen.data.chunks import chunks

    rows = [[f"{0.001 * k:.3f}", str(np.sin(0.001 * k)), "0.5", "1.0", "2.0"] for k in range(40)]
    for k in (0, 1, 2):
        rows[k][3] = ""  # tau1 not yet published
    rows[-1][1] = "nan"
    text = ",".join(HEADER) + "\n" + "\n".join(",".join(r) for r in rows) + "\n"
    path = tmp_path / "run.csv"
    path.write_text(text)
    r = read_recording(path, N)
    assert r.t.size == 36 and r.t[0] == 0.003 and np.all(np.isfinite(r.tau))
    assert r.read_note.startswith("3 row(s) at the start and 1 at the end miss a value")
    assert "3 row(s) at the start" in condition(r).note
    path.write_text(text.replace("\n0.039,", "\n0.039,1,", 1).replace("0.039,1,nan", "0.039,nan"))
    with pytest.raises(InputError, match="line 41, column q1"):
        list(chunks(path, N, rows=16))
    first = next(chunks(path, N, rows=16))
    assert first.t[0] == 0.003 and first.read_note.startswith("3 row(s) at the start and 0 at the end")
    rows[20][2] = ""
    path.write_text(",".join(HEADER) + "\n" + "\n".join(",".join(r) for r in rows) + "\n")
    assert error_of(path).startswith("run.csv: line 22, column q2: nan (NaN or infinite value; missing values")


@pytest.mark.parametrize("layout", ["savetxt", "comments", "pandas", "trailing"])
def test_headers_as_common_writers_make_them(tmp_path, layout):
    """numpy.savetxt writes its header as a comment (`# t,q1,...`), loggers put '#' lines above the
    header, pandas' to_csv writes an unnamed row index first, a loop writing `value,` ends every line
    with a comma: the values read are those of the plain file, whole and in blocks, and a bad cell is
    named at its line in the file."""
    from dyngen.data.chunks import chunks

    rows = [[0.01 * k, np.sin(0.1 * k), 0.2 * k, 1.0 + k, 2.0] for k in range(30)]
    plain = read_recording(write(tmp_path, HEADER, rows, "plain.csv"), N)
    above, header, body = {"savetxt": (["# t,q1,q2,tau1,tau2"], [], rows),
                           "comments": (["# logged by rig 3", "#rate: 100 Hz"], HEADER, rows),
                           "pandas": ([], [""] + HEADER, [[k] + row for k, row in enumerate(rows)]),
                           "trailing": ([], HEADER + [""], [row + [""] for row in rows])}[layout]
    lines = above + ([",".join(header)] if header else []) + [",".join(str(v) for v in row) for row in body]
    path = tmp_path / "run.csv"
    path.write_text("\n".join(lines) + "\n")
    for r in (read_recording(path, N), next(chunks(path, N, rows=8))):
        assert np.array_equal(r.t, plain.t[:r.t.size]) and np.array_equal(r.q, plain.q[:r.t.size])
        assert np.array_equal(r.tau, plain.tau[:r.t.size]) and not r.extra
    bad = len(lines) - 10  # the line number of the 10th-last row, 1-based, in the file as written
    lines[bad - 1] = lines[bad - 1].replace("2.0", "x", 1) if layout != "pandas" else lines[bad - 1][:-3] + "x"
    path.write_text("\n".join(lines) + "\n")
    assert error_of(path).startswith(f"run.csv: line {bad}, column tau2: not a number")
    with pytest.raises(InputError, match=f"line {bad}, column tau2"):
        list(chunks(path, N, rows=8))


def test_a_bus_s_errors_are_repaired_on_the_real_lwr4_log(tmp_path):
    """The real LWR4+ log with positions only, then with five positions (0.1 rad) and five torques (200 Nm)
    wrong for one row each and joint 1's angle logged in [0, 2 pi): the conditioning is the clean log's
    (same automatic cutoff; positions and torques within the encoder's and the filter's rounding), and
    a warning counts the spikes and names the wrapped joint. Before, the spikes made the position
    noise 0.004 rad and the cutoff 0.6 Hz (40 Hz clean), and the wrap made the log unusable."""
    from conftest import ROOT

    header, *lines = (ROOT / "examples" / "lwr4-real" / "measurement_1.csv").read_text().splitlines()
    names = header.split(",")
    keep = [0] + [names.index(f"{p}{j}") for p in ("q", "tau") for j in range(1, 8)]
    data = np.array([[float(x) for x in line.split(",")] for line in lines])[:, keep]
    head = ",".join(names[k] for k in keep)

    def written(name, d):
        path = tmp_path / name
        path.write_text(head + "\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in d) + "\n")
        return condition(read_recording(path, 7))

    clean = written("clean.csv", data)
    bad = data.copy()
    rows = np.random.default_rng(0).choice(np.arange(100, data.shape[0] - 100), 10, replace=False)
    bad[rows[:5], 3] += 0.1  # q3
    bad[rows[5:], 9] -= 200.0  # tau2
    bad[:, 1] = np.mod(bad[:, 1], 2 * np.pi)  # q1 crosses 0: it wraps
    sig = written("glitched.csv", bad)
    assert sig.cutoff == pytest.approx(clean.cutoff, rel=1e-6) and clean.cutoff > 10
    inner = clean.inner()
    assert np.max(np.abs(np.mod(sig.q - clean.q + np.pi, 2 * np.pi) - np.pi)[inner]) < 1e-4
    assert np.max(np.abs(sig.tau - clean.tau)[inner]) < 0.05 * np.max(np.abs(clean.tau))
    said = " ".join(sig.warnings)
    assert "5 spike(s) in q (joint(s) 3" in said and "5 spike(s) in tau (joint(s) 2" in said
    assert "positions of joint(s) 1 wrap around a full turn" in said
