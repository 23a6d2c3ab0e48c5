"""Recordings as loggers write them: the pathologies of real logs, applied to a clean recording.

A controller samples the arm on a regular clock; a logger (a ROS subscriber, a bag recorder, a
script polling the robot) writes rows at its own, irregular times, each row the latest sample it
has, stamped when it is written. That makes, from one clean recording (CSV text, `t, q.., tau..`
as tests/simulation/mujoco_measurements.csv_text writes it):

  repeated   the same sample written twice (a new stamp, every value repeated), a share of rows
  dropped    samples never written, a share of rows (the stamps keep the gap)
  jittered   stamps late by a random delay of up to `late` s (the values are the clock's)
  polled     the logger's own clock: writes every period +- jitter, with stalls now and then,
             each row the latest sample, stamped when written (repeated rows, dropped samples
             and late stamps at once: the franka_ros logs of Gaz et al. 2019 have 5.5 % repeated
             rows and steps of 0.7-8.8 ms at a nominal 1 kHz)
  held       some columns (e.g. the torques) updated only every `every`-th sample (mixed rates)
  wandering  every sample written once (5.5 % twice), stamped when it arrives: its latency wanders
             smoothly (a queue filling and draining, a driver's receive-time clock), so the stamps'
             error lives at tens of Hz and the positions over the row index stay smooth

The sample values are never altered, only repeated, left out or stamped elsewhere: what a
diagnosis can do with such a log is what it could do with the clean one, or it must say why not.
"""

from __future__ import annotations

import io

import numpy as np


def parse(text: str):
    header, _, body = text.partition("\n")
    return header, np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2)


def unparse(header: str, data: np.ndarray) -> str:
    out = io.StringIO()
    np.savetxt(out, data, fmt="%.12g", delimiter=",", header=header, comments="")
    return out.getvalue()


def repeated(text: str, share: float, seed: int) -> str:
    """Every row written twice with probability `share`, the copy stamped between it and the next."""
    header, data = parse(text)
    rng = np.random.default_rng(seed)
    twice = rng.random(data.shape[0] - 1) < share
    rows = []
    for k in range(data.shape[0]):
        rows.append(data[k])
        if k < data.shape[0] - 1 and twice[k]:
            copy = data[k].copy()
            copy[0] = data[k, 0] + rng.uniform(0.2, 0.8) * (data[k + 1, 0] - data[k, 0])
            rows.append(copy)
    return unparse(header, np.array(rows))


def dropped(text: str, share: float, seed: int) -> str:
    """Rows left out with probability `share` (never the first or the last)."""
    header, data = parse(text)
    keep = np.random.default_rng(seed).random(data.shape[0]) >= share
    keep[0] = keep[-1] = True
    return unparse(header, data[keep])


def jittered(text: str, late: float, seed: int) -> str:
    """Every stamp late by a uniform delay in [0, late] s (kept increasing)."""
    header, data = parse(text)
    t = data[:, 0] + np.random.default_rng(seed).uniform(0.0, late, data.shape[0])
    data = data.copy()
    data[:, 0] = np.maximum.accumulate(t + 1e-9 * np.arange(t.size))
    return unparse(header, data)


def polled(text: str, seed: int, jitter: float = 0.3, stall_share: float = 0.01, stall: float = 6e-3) -> str:
    """A logger polling the latest sample on its own clock: nominally every sample period, each
    write late by up to `jitter` periods, and with probability `stall_share` a stall of up to
    `stall` s before the write. Rows are stamped at the write."""
    header, data = parse(text)
    t = data[:, 0]
    period = float(np.median(np.diff(t)))
    rng = np.random.default_rng(seed)
    writes, now = [], t[0] + 0.1 * period
    while now < t[-1]:
        writes.append(now)
        step = period * (1.0 + rng.uniform(-jitter, jitter))
        if rng.random() < stall_share:
            step += rng.uniform(0.5, 1.0) * stall
        now += step
    writes = np.array(writes)
    latest = np.searchsorted(t, writes, side="right") - 1  # the last sample taken before the write
    rows = data[latest].copy()
    rows[:, 0] = writes
    return unparse(header, rows)


def glitched(text: str, seed: int, share: float = 0.001) -> str:
    """A sensor bus's errors: with probability `share` per row one position (off by 0.05-0.5 rad) or one
    torque (off by 20-200 Nm) wrong for that row alone, and joint 1's angle logged in [0, 2 pi)."""
    header, data = parse(text)
    names = header.split(",")
    q = [k for k, n in enumerate(names) if n[:1] == "q" and n[1:].isdigit()]
    tau = [k for k, n in enumerate(names) if n.startswith("tau") and n[3:].isdigit()]
    rng = np.random.default_rng(seed)
    data = data.copy()
    for row in np.flatnonzero(rng.random(data.shape[0]) < share)[1:]:
        position = rng.random() < 0.5
        column = rng.choice(q if position else tau)
        data[row, column] += rng.choice([-1.0, 1.0]) * rng.uniform(*((0.05, 0.5) if position else (20.0, 200.0)))
    data[:, q[0]] = np.mod(data[:, q[0]], 2.0 * np.pi)
    return unparse(header, data)


def held(text: str, prefix: str, every: int) -> str:
    """Columns `prefix`1.. (e.g. "tau") updated only every `every`-th row, held in between."""
    header, data = parse(text)
    names = header.split(",")
    columns = [k for k, n in enumerate(names) if n.startswith(prefix) and n[len(prefix):].isdigit()]
    data = data.copy()
    source = (np.arange(data.shape[0]) // every) * every
    data[:, columns] = data[source][:, columns]
    return unparse(header, data)


def wandering(text: str, seed: int, rms: float = 0.5e-3, hz: float = 20.0, base: float = 0.5e-3,
              share: float = 0.055) -> str:
    """Each sample stamped at its time + a latency of `base` plus a smooth random wander (white noise
    through a 2nd-order low-pass at `hz`, scaled to `rms` s, the latency kept above 0.05 ms); with
    probability `share` a sample is written again, stamped between it and the next."""
    from scipy import signal

    header, data = parse(text)
    t = data[:, 0]
    rng = np.random.default_rng(seed)
    lead = 2000
    wander = signal.sosfilt(signal.butter(2, hz, fs=1.0 / float(np.median(np.diff(t))), output="sos"),
                            rng.standard_normal(t.size + lead))[lead:]
    stamp = t + np.maximum(base + rms * wander / wander.std(), 0.05e-3)
    twice = rng.random(t.size) < share
    twice[-1] = False
    source = np.repeat(np.arange(t.size), 1 + twice)
    again = np.r_[False, source[1:] == source[:-1]]
    rows = data[source].copy()
    rows[:, 0] = stamp[source]
    k = source[again]
    rows[again, 0] = stamp[k] + rng.uniform(0.2, 0.8, k.size) * (stamp[k + 1] - stamp[k])
    rows[:, 0] = np.maximum.accumulate(rows[:, 0] + 1e-9 * np.arange(rows.shape[0]))
    return unparse(header, rows)
