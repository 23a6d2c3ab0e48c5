"""Parquet files and ROS 2 bags give the Recording the same data give as CSV (the CSV reader is
the oracle), and every bad file fails with one line naming the file and where."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dyngen.data import read_recording
from dyngen.data.rosbag import BagReading
from dyngen.errors import InputError

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")
pytest.importorskip("rosbags")
from rosbags.rosbag2 import Writer  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
N = 3
STORE = get_typestore(Stores.ROS2_HUMBLE)
JS = STORE.types["sensor_msgs/msg/JointState"]
HEADER = STORE.types["std_msgs/msg/Header"]
TIME = STORE.types["builtin_interfaces/msg/Time"]
ARRAY = STORE.types["std_msgs/msg/Float64MultiArray"]
LAYOUT = STORE.types["std_msgs/msg/MultiArrayLayout"]


def signals(rows=40):
    """Sensor-like columns: stamps at 100 Hz from 1.5 s, quantised positions, noisy torques."""
    rng = np.random.default_rng(0)
    t = 1.5 + 0.01 * np.arange(rows)
    q = np.round(np.sin(np.outer(t, [1.0, 0.7, 1.3])) / 1e-4) * 1e-4
    qd = np.cos(np.outer(t, [1.0, 0.7, 1.3]))
    tau = 3 * q + 0.05 * rng.standard_normal(q.shape)
    return t, q, qd, tau


def write_csv(path, t, q, qd, tau):
    header = ["t"] + [f"{p}{j}" for p in ("q", "qd", "tau") for j in range(1, N + 1)]
    rows = np.column_stack([t, q, qd, tau])
    path.write_text(",".join(header) + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")
    return path


def write_parquet(path, t, q, qd, tau, **change):
    columns = {"t": t, **{f"q{j + 1}": q[:, j] for j in range(N)}, **{f"qd{j + 1}": qd[:, j] for j in range(N)},
               **{f"tau{j + 1}": tau[:, j] for j in range(N)}}
    columns.update(change)
    pq.write_table(pa.table(columns), path)
    return path


def state(stamp, names, position, velocity, effort):
    sec = int(np.floor(stamp))
    return JS(header=HEADER(stamp=TIME(sec=sec, nanosec=int(round((stamp - sec) * 1e9))), frame_id=""),
              name=list(names), position=np.asarray(position, float), velocity=np.asarray(velocity, float),
              effort=np.asarray(effort, float))


def write_bag(folder, t, q, qd, tau, names=("a", "b", "c"), commands=None, shuffle=False):
    with Writer(folder, version=9) as w:
        c = w.add_connection("/joint_states", JS.__msgtype__, typestore=STORE)
        k = w.add_connection("/effort_controller/commands", ARRAY.__msgtype__, typestore=STORE) \
            if commands is not None else None
        for i in range(t.size):
            order = [2, 0, 1] if shuffle and i % 2 else list(range(len(names)))
            m = state(t[i], [names[o] for o in order], q[i, order], qd[i, order], tau[i, order])
            clock = int(round(t[i] * 1e9))
            if commands is not None:
                w.write(k, clock - 1000, STORE.serialize_cdr(ARRAY(layout=LAYOUT(dim=[], data_offset=0),
                                                                   data=commands[i]), ARRAY.__msgtype__))
            w.write(c, clock, STORE.serialize_cdr(m, JS.__msgtype__))
    return folder


def same(a, b):
    assert np.array_equal(a.q, b.q) and np.array_equal(a.qd, b.qd) and np.array_equal(a.tau, b.tau)
    assert a.qdd is None and b.qdd is None


def test_parquet_equals_csv(tmp_path):
    data = signals()
    csv = read_recording(write_csv(tmp_path / "run.csv", *data), N)
    par = read_recording(write_parquet(tmp_path / "run.parquet", *data), N)
    same(csv, par)
    assert np.array_equal(csv.t, par.t)


def test_bag_equals_csv(tmp_path):
    t, q, qd, tau = signals()
    csv = read_recording(write_csv(tmp_path / "run.csv", t, q, qd, tau), N)
    bag = read_recording(write_bag(tmp_path / "run_bag", t, q, qd, tau, shuffle=True), N)
    same(csv, bag)  # joints reordered by name in every other message
    assert np.allclose(bag.t, t - t[0], atol=1e-9, rtol=0)  # stamps in ns, relative to the first
    # the storage file stands for its folder
    storage = next((tmp_path / "run_bag").glob("*.db3"))
    same(csv, read_recording(storage, N))


def test_bag_joints_read_by_the_robot_s_names(tmp_path):
    """A driver that publishes the arm's joints in another order (the UR driver: shoulder_pan last) and a
    hand's joints beside them (franka: the fingers): with the URDF's names the chain's joints are read
    by name, the others left out and said; without names, the count is refused in one line."""
    t, q, qd, tau = signals()
    csv = read_recording(write_csv(tmp_path / "run.csv", t, q, qd, tau), N)
    order, names = [1, 2, 0], ("shoulder_lift", "elbow", "shoulder_pan")  # chain: pan, lift, elbow
    extra = np.column_stack([q[:, order], 0.02 * np.ones(t.size)])  # a finger
    with Writer(tmp_path / "ur_bag", version=9) as w:
        c = w.add_connection("/joint_states", JS.__msgtype__, typestore=STORE)
        for i in range(t.size):
            m = state(t[i], [*names, "finger"], extra[i].copy(), np.r_[qd[i, order], 0.0], np.r_[tau[i, order], 0.0])
            w.write(c, int(round(t[i] * 1e9)), STORE.serialize_cdr(m, JS.__msgtype__))
    chain = ("shoulder_pan", "shoulder_lift", "elbow")
    r = read_recording(tmp_path / "ur_bag", N, bag=BagReading(joints=chain))
    same(csv, r)
    assert "finger not in the chain, left out" in r.read_note and "shoulder_pan, shoulder_lift, elbow" in r.read_note
    assert "the robot has 3 joints but the message names 4" in one_line(tmp_path / "ur_bag")
    assert "no joint named wrist" in one_line(tmp_path / "ur_bag", bag=BagReading(joints=("shoulder_pan", "wrist",
                                                                                          "elbow")))


def test_bag_commanded_effort(tmp_path):
    t, q, qd, tau = signals()
    commanded = -tau + 1.0
    bag = write_bag(tmp_path / "cmd_bag", t, q, qd, tau, commands=commanded)
    r = read_recording(bag, N, bag=BagReading(effort_topic="/effort_controller/commands"))
    assert np.array_equal(r.tau, commanded) and np.array_equal(r.q, q)


def test_glob_reads_every_match_in_order(tmp_path):
    from dyngen.data.paths import expand

    data = signals()
    for k in (2, 0, 1):
        write_parquet(tmp_path / f"robot{k}.parquet", *data)
    assert [Path(p).name for p in expand([str(tmp_path / "robot*.parquet")])] == \
        ["robot0.parquet", "robot1.parquet", "robot2.parquet"]
    with pytest.raises(InputError, match="no file matches"):
        expand([str(tmp_path / "none*.csv")])


def one_line(path, **kw) -> str:
    with pytest.raises(InputError) as err:
        read_recording(path, N, **kw)
    text = str(err.value)
    assert "\n" not in text and len(text) < 400
    return text


def test_bad_parquet_files(tmp_path):
    t, q, qd, tau = signals()
    text = one_line(write_parquet(tmp_path / "nan.parquet", t, q, qd, tau, q2=np.where(np.arange(t.size) == 7,
                                                                                        np.nan, q[:, 1])))
    assert "nan.parquet: row 8, column q2" in text
    text = one_line(write_parquet(tmp_path / "null.parquet", t, q, qd, tau,
                                  tau1=pa.array([None if k == 3 else 1.0 for k in range(t.size)])))
    assert "null.parquet: row 4, column tau1: missing value" in text
    text = one_line(write_parquet(tmp_path / "text.parquet", t, q, qd, tau, tau3=["x"] * t.size))
    assert "column tau3" in text and "not numbers" in text
    back = t.copy()
    back[5] = back[4]
    assert "row 6, column t: time does not increase" in one_line(write_parquet(tmp_path / "t.parquet", back, q, qd, tau))
    table = {"t": t, **{f"q{j}": q[:, 0] for j in (1, 2)}, **{f"tau{j}": t for j in (1, 2, 3)}}
    pq.write_table(pa.table(table), tmp_path / "six.parquet")
    assert "six.parquet: columns: the robot has 3 joints but the file has only q1..q2 (missing q3)" in one_line(tmp_path / "six.parquet")
    (tmp_path / "junk.parquet").write_bytes(b"PAR1 this is not parquet")
    assert "junk.parquet: not a readable Parquet file" in one_line(tmp_path / "junk.parquet")
    (tmp_path / "dir.parquet").mkdir()
    assert "not a regular file" in one_line(tmp_path / "dir.parquet")


def test_bad_bags(tmp_path):
    t, q, qd, tau = signals()
    bag = write_bag(tmp_path / "two_bag", t, q[:, :2], qd[:, :2], tau[:, :2], names=("a", "b"))
    assert "the robot has 3 joints but the message names 2" in one_line(bag)
    bag = write_bag(tmp_path / "nan_bag", t, np.where(np.arange(t.size)[:, None] == 9, np.inf, q), qd, tau)
    assert "message 10 on /joint_states, column q1" in one_line(bag)
    assert "topic /nope: not in the bag" in one_line(write_bag(tmp_path / "ok_bag", t, q, qd, tau),
                                                       bag=BagReading(effort_topic="/nope"))
    (tmp_path / "link_bag").mkdir()
    (tmp_path / "link_bag" / "metadata.yaml").symlink_to("/etc/passwd")
    assert "not a regular file" in one_line(tmp_path / "link_bag")
    broken = tmp_path / "broken_bag"
    broken.mkdir()
    (broken / "metadata.yaml").write_text("rosbag2_bagfile_information: {version: 99}\n")
    assert "broken_bag: not a readable ROS 2 bag" in one_line(broken)


def test_command_reports_a_bad_file_in_one_line(tmp_path):
    (tmp_path / "junk.parquet").write_bytes(b"\x00" * 100)
    run = subprocess.run([sys.executable, "-m", "dyngen", "identify", str(ROOT / "examples/lwr.yaml"), "--kind",
                          "gravity", "--data", str(tmp_path / "junk.parquet"), "-o", str(tmp_path / "out.yaml")],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and run.stderr.count("\n") == 1
    assert run.stderr.startswith("dyngen: error: junk.parquet: not a readable Parquet file")
    assert not (tmp_path / "out.yaml").exists()
