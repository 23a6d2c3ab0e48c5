"""A ROS 2 bag's joint states as a Recording, through rosbags (the optional extra `formats`), tau the
measured efforts or `effort_topic`'s latest before each state (docs/many-recordings.md). Messages
are decoded by rosbags' CDR reader for these fixed types only: nothing in the bag is executed."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError, shorten
from ..untrusted import MAX_CSV_BYTES, regular_folder
from .columnar import BAG_FILES, _module
from .recording import Recording, check_header, from_columns

JOINT_STATE = "sensor_msgs/msg/JointState"
ARRAY = "std_msgs/msg/Float64MultiArray"


@dataclass(frozen=True)
class BagReading:
    """How a bag is read: the commanded effort's topic (None: the joint states' measured efforts), and
    the robot's joint names in chain order (a URDF's; a driver may publish its joints in another order,
    and a hand's beside the arm's). Without names, the first message's order is the chain's, and it
    must name exactly the robot's joints."""

    effort_topic: str | None = None
    joints: tuple = ()


def bag_folder(path) -> Path:
    path = Path(path)
    if path.suffix.lower() in BAG_FILES and not path.is_dir():
        return path.parent
    return path


def _stamp(message) -> float:
    return message.header.stamp.sec + 1e-9 * message.header.stamp.nanosec


def read_bag(path, dof: int, require_torques: bool = True, bag: BagReading | None = None) -> Recording:
    folder = bag_folder(path)
    name = folder.name
    regular_folder(folder, MAX_CSV_BYTES)
    rosbag2 = _module("rosbags.rosbag2", folder)
    typesys = _module("rosbags.typesys", folder)
    store = typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
    try:
        with rosbag2.Reader(folder) as reader:
            return _read(reader, store, name, dof, require_torques, bag or BagReading())
    except InputError:
        raise
    except Exception as err:  # noqa: BLE001 -- a broken bag may raise anything from the library: one line
        raise InputError(name, "", f"not a readable ROS 2 bag ({shorten(err, 200)})") from None


def _topic(reader, name, wanted=None) -> object:
    states = [c for c in reader.connections if c.msgtype == JOINT_STATE]
    if wanted is not None:
        found = [c for c in reader.connections if c.topic == wanted]
        if not found:
            raise InputError(name, f"topic {shorten(wanted)}", "not in the bag (topics: "
                             f"{shorten(', '.join(sorted({c.topic for c in reader.connections})), 200)})")
        if found[0].msgtype not in (JOINT_STATE, ARRAY):
            raise InputError(name, f"topic {shorten(wanted)}", f"type {shorten(found[0].msgtype)}; expected "
                             f"{JOINT_STATE} or {ARRAY}")
        return found
    named = [c for c in states if c.topic.endswith("joint_states")]
    chosen = named or states
    if not chosen:
        raise InputError(name, "", f"no {JOINT_STATE} topic in the bag")
    if len({c.topic for c in chosen}) > 1:
        raise InputError(name, "", "several joint state topics (" + shorten(", ".join(sorted({c.topic for c in chosen})),
                                                                        200) + "); keep one in the bag")
    return chosen


def _read(reader, store, name, dof, require_torques, bag: BagReading) -> Recording:
    states = _topic(reader, name)
    topic = states[0].topic
    effort_topic = bag.effort_topic
    commands = _topic(reader, name, effort_topic) if effort_topic else None
    joints, first, stamps, clock, q, qd, tau, others = None, None, [], [], [], [], [], []
    for k, (connection, time, raw) in enumerate(reader.messages(connections=states)):
        m = store.deserialize_cdr(raw, connection.msgtype)
        where = f"message {k + 1} on {topic}"
        names = [str(n) for n in m.name]
        if len(set(names)) != len(names):
            raise InputError(name, where, "a joint is named twice")
        if joints is None:
            first, (joints, others) = names, _chain(name, where, dof, names, bag.joints)
        order = _order(name, where, joints, names)
        position, velocity, effort = (np.asarray(v, dtype=float) for v in (m.position, m.velocity, m.effort))
        for label, values, needed in (("position", position, True), ("velocity", velocity, False),
                                      ("effort", effort, require_torques and not effort_topic)):
            if values.size not in ((0, len(names)) if not needed else (len(names),)):
                raise InputError(name, where, f"{values.size} {label} values for {len(names)} joints")
        stamps.append(_stamp(m))
        clock.append(time)
        q.append(position[order])
        qd.append(velocity[order] if velocity.size else None)
        tau.append(effort[order] if effort.size else None)
    if not stamps:
        raise InputError(name, f"topic {topic}", "no messages")
    clock = np.asarray(clock)
    keep = np.ones(len(stamps), dtype=bool)
    if commands is not None:
        tau, keep = _commanded(reader, store, name, commands, joints, clock)
    elif any(x is None for x in tau):  # efforts are optional only when not required (checked above)
        tau = None
    velocities = None if any(x is None for x in qd) else np.vstack(qd)[keep]
    header = ["t", *(f"q{j}" for j in range(1, dof + 1))]
    blocks = [np.asarray(stamps)[keep, None] - stamps[0], np.vstack(q)[keep]]
    if velocities is not None:
        header += [f"qd{j}" for j in range(1, dof + 1)]
        blocks.append(velocities)
    if tau is not None:
        header += [f"tau{j}" for j in range(1, dof + 1)]
        blocks.append(np.vstack(tau) if isinstance(tau, list) else tau)
    columns = check_header(name, header, dof, require_torques)
    rows = np.flatnonzero(keep)
    out = from_columns(name, header, columns, np.hstack(blocks), dof,
                       where=lambda row: f"message {rows[row] + 1} on {topic}")
    if others or joints != first:
        said = f"joints read by name in the robot's order ({shorten(', '.join(joints), 160)})" + (
            f"; {shorten(', '.join(others), 120)} not in the chain, left out" if others else "")
        out.read_note = "; ".join(x for x in (said, out.read_note) if x)
    return out


def _chain(name, where, dof, names, robot_joints) -> tuple[list, list]:
    """(the chain's joint names in its order, the other joints the message names), from the first message."""
    if not robot_joints:
        if len(names) != dof:
            raise InputError(name, where, f"the robot has {dof} joints but the message names {len(names)} "
                             f"({shorten(', '.join(names), 120)}); a URDF names its joints, so that they are "
                             "read by name")
        return names, []
    missing = [j for j in robot_joints if j not in names]
    if missing:
        raise InputError(name, where, f"no joint named {shorten(', '.join(missing), 120)} (the message names "
                         f"{shorten(', '.join(names), 160)})")
    return list(robot_joints), [n for n in names if n not in robot_joints]


def _order(name, where, joints, names) -> list:
    """Where each of `joints` is in this message's `names` (which may hold more)."""
    if names[:len(joints)] == joints:
        return list(range(len(joints)))
    missing = [j for j in joints if j not in names]
    if missing:
        raise InputError(name, where, f"joints {shorten(', '.join(names), 120)}; the first message named "
                         f"{shorten(', '.join(joints), 120)}")
    return [names.index(j) for j in joints]


def _commanded(reader, store, name, connections, joints, clock):
    """(tau (kept states, N), keep): the latest command at or before each joint state."""
    topic = connections[0].topic
    times, values = [], []
    for k, (connection, time, raw) in enumerate(reader.messages(connections=connections)):
        m = store.deserialize_cdr(raw, connection.msgtype)
        where = f"message {k + 1} on {topic}"
        if connection.msgtype == ARRAY:
            v = np.asarray(m.data, dtype=float)
        else:
            v = np.asarray(m.effort, dtype=float)[_order(name, where, joints, [str(n) for n in m.name])] \
                if len(m.effort) == len(m.name) else np.zeros(0)
        if v.size != len(joints):
            raise InputError(name, where, f"{v.size} effort values for {len(joints)} joints")
        times.append(time)
        values.append(v)
    if not times:
        raise InputError(name, f"topic {topic}", "no messages")
    times = np.asarray(times)
    if np.any(np.diff(times) < 0):
        raise InputError(name, f"topic {topic}", "messages out of order in the bag")
    latest = np.searchsorted(times, clock, side="right") - 1
    keep = latest >= 0
    if not keep.any():
        raise InputError(name, f"topic {topic}", "every command comes after the last joint state")
    return np.vstack(values)[latest[keep]], keep
