"""Synthetic "measured" joint torques from MuJoCo, with effects that dyngen's model does not contain.

An independent engine, not dyngen's generated code. The rigid body is dyngen's MJCF export
`to_mjcf(robot, p)`; the effects are then put into that model (MuJoCo's own terms) or onto the
torque signal (a sensor):

  viscous   Fv qd            joint `damping` (a passive force; mj_inverse adds it back)
  coulomb   Fc sign(qd)      joint `frictionloss`, a constraint (see below)
  armature  Ia qdd           joint `armature` (added to the diagonal of M)
  payload   10 parameters    one more body, without a joint, in the last link at DH frame N
  tilt      gravity          `option gravity`: the base turned by an angle about a horizontal axis
  stribeck  computed here    sign(qd) (Fs - Fc) exp(-(qd / vs)^2), the excess of static over
                             Coulomb friction; MuJoCo has no Stribeck law, and mj_inverse leaves
                             qfrc_applied out of its result, so the term is added to the torque
  time_shift, gain, offset, noise: the sensor,
      tau_measured(t) = (1 + gain) tau(t - shift) + offset + sigma * N(0, 1)
  (the torque lags the positions by `shift`; tau(t - shift) is evaluated at the trajectory's
  state at t - shift, so the trajectory must be callable at any time).

Torques come from mj_inverse at the prescribed (q, qd, qdd), not from a forward simulation
with a tracking controller: inverse dynamics is exact at every sample (no tracking error, no
integration error), so the only differences from dyngen's rnea are the injected effects.

Coulomb through `frictionloss`: MuJoCo's inverse force of a friction-loss row is the soft
constraint law f = -clip(jar / R, -Fc, Fc) with jar = qdd + B qd (reference acceleration -B qd)
and R = (1 - d) / d * A_ii. With solreffriction = "-1e6 -1e6" (direct stiffness and damping,
B = 1e6 1/s; stiffness plays no part for friction) and solimpfriction d = 0.9999 the law is
Fc sign(qd + qdd / B) except where |qd + qdd / B| < Fc R / B (about 1e-8 rad/s for the LWR):
a sharp Fc sign(qd) once |qd| exceeds |qdd| / 1e6. At qd = 0 it follows sign(qdd), like
static friction. Joint-limit constraints are switched off (mjDSBL_LIMIT): the trajectories are
checked against the limits separately, and a limit force is not an effect under study.
"""

from __future__ import annotations

import io
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import mujoco
import numpy as np

from dyngen.atomic import write_file
from dyngen.description import load_robot
from dyngen.export import to_mjcf
from dyngen.export.frames import link_matrix, placements, quaternion, vec

# Friction-loss constraint settings that make MuJoCo's inverse Coulomb force sharp (see above).
FRICTION_SOLREF = "-1e6 -1e6"
FRICTION_SOLIMP = "0.9999 0.9999 0.001 0.5 2"


@dataclass(frozen=True)
class Trajectory:
    """Sample times t (T,) and the motion as a function of time: at(times) -> q, qd, qdd (T x N)."""

    t: np.ndarray
    at: Callable

    def states(self, shift: float = 0.0):
        return self.at(np.asarray(self.t, dtype=float) - shift)


@dataclass(frozen=True)
class Effects:
    """Unmodelled effects, per joint keyed by the 1-based joint number. Units: Nm (N for a
    prismatic joint), Nm s/rad, kg m^2, s, and relative for the gain."""

    coulomb: dict = field(default_factory=dict)  # joint -> Fc
    viscous: dict = field(default_factory=dict)  # joint -> Fv
    stribeck: dict = field(default_factory=dict)  # joint -> (Fs - Fc, vs): the excess over coulomb
    armature: dict = field(default_factory=dict)  # joint -> Ia
    offset: dict = field(default_factory=dict)  # joint -> torque offset
    gain: dict = field(default_factory=dict)  # joint -> g, measured = (1 + g) * true
    payload: np.ndarray | None = None  # 10 dynamic parameters (docs/conventions.md) in DH frame N
    tilt_deg: float = 0.0  # the base turned by this angle about tilt_axis
    tilt_axis: tuple = (1.0, 0.0, 0.0)  # horizontal axis in the base frame
    time_shift: float = 0.0  # s, the torque lags the positions

    def per_joint(self):
        return {"coulomb": self.coulomb, "viscous": self.viscous, "stribeck": self.stribeck,
                "armature": self.armature, "offset": self.offset, "gain": self.gain}


@dataclass(frozen=True)
class Measurement:
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray


def tilted_gravity(gravity, angle_deg: float, axis) -> np.ndarray:
    """Gravity in the base frame once the base is turned by angle_deg about axis (right hand):
    g_base = R^T g, R = Rodrigues(axis, angle)."""
    u = np.asarray(axis, dtype=float)
    u = u / np.linalg.norm(u)
    th = np.radians(angle_deg)
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    R = np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K
    return R.T @ np.asarray(gravity, dtype=float)


def _check(robot, effects: Effects) -> None:
    n = robot.dof
    for name, table in effects.per_joint().items():
        for joint, value in table.items():
            if not (isinstance(joint, int) and 1 <= joint <= n):
                raise ValueError(f"{name}: joint {joint!r} is not one of 1..{n}")
            if not np.all(np.isfinite(value)):
                raise ValueError(f"{name}: joint {joint}: {value!r} is not finite")
            if name in ("coulomb", "viscous", "armature") and value < 0:
                raise ValueError(f"{name}: joint {joint}: {value!r} is negative")
            if name == "stribeck" and (value[0] < 0 or value[1] <= 0):
                raise ValueError(f"stribeck: joint {joint}: need Fs - Fc >= 0 and vs > 0, got {value!r}")
    if effects.payload is not None and np.asarray(effects.payload).shape != (10,):
        raise ValueError("payload: expected 10 dynamic parameters")


def simulator_xml(robot, p, effects: Effects = Effects()) -> str:
    """dyngen's MJCF of (robot, p) with the effects MuJoCo models itself (see the module doc)."""
    _check(robot, effects)
    root = ET.fromstring(to_mjcf(robot, p))
    joints = {j.get("name"): j for j in root.iter("joint")}
    for attribute, table in (("damping", effects.viscous), ("armature", effects.armature)):
        for i, value in table.items():
            joints[f"joint_{i}"].set(attribute, repr(float(value)))
    for i, value in effects.coulomb.items():
        joints[f"joint_{i}"].set("frictionloss", repr(float(value)))
        joints[f"joint_{i}"].set("solreffriction", FRICTION_SOLREF)
        joints[f"joint_{i}"].set("solimpfriction", FRICTION_SOLIMP)
    if effects.tilt_deg:
        option = root.find("option")
        option.set("gravity", vec(tilted_gravity(option.get("gravity").split(), effects.tilt_deg, effects.tilt_axis)))
    if effects.payload is not None:
        pl = np.asarray(effects.payload, dtype=float)
        last = next(b for b in root.iter("body") if b.get("name") == f"link_{robot.dof}")
        post = placements(robot)[-1].post  # DH frame N in the last joint's frame
        body = ET.SubElement(last, "body", name="payload", pos=vec(post[:3, 3]), quat=vec(quaternion(post[:3, :3])))
        I = link_matrix(pl)
        ET.SubElement(body, "inertial", pos=vec(pl[1:4]), mass=repr(float(pl[0])),
                      fullinertia=vec([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]))
    return ET.tostring(root, encoding="unicode") + "\n"


def simulator(robot, p, effects: Effects = Effects()) -> mujoco.MjModel:
    model = mujoco.MjModel.from_xml_string(simulator_xml(robot, p, effects))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_LIMIT
    return model


def inverse_torques(model: mujoco.MjModel, q, qd, qdd) -> np.ndarray:
    """mj_inverse at every sample (T x N)."""
    data = mujoco.MjData(model)
    tau = np.empty_like(np.asarray(q, dtype=float))
    for k in range(tau.shape[0]):
        data.qpos[:], data.qvel[:], data.qacc[:] = q[k], qd[k], qdd[k]
        mujoco.mj_inverse(model, data)
        tau[k] = data.qfrc_inverse
    return tau


def stribeck_torque(effects: Effects, qd) -> np.ndarray:
    out = np.zeros_like(qd)
    for i, (excess, vs) in effects.stribeck.items():
        v = qd[:, i - 1]
        out[:, i - 1] = np.sign(v) * excess * np.exp(-(v / vs) ** 2)
    return out


def measure(robot, p, trajectory: Trajectory, effects: Effects = Effects(), noise=0.0, seed=0) -> Measurement:
    """The "measured" samples: robot (a dyngen Robot or its YAML path), dynamic parameters p
    (10N) of the simulated arm, trajectory, effects, noise sigma (scalar or per joint) and seed
    (anything np.random.default_rng accepts)."""
    if isinstance(robot, (str, Path)):
        robot = load_robot(robot)
    t = np.asarray(trajectory.t, dtype=float)
    q, qd, qdd = trajectory.states()
    sq, sqd, sqdd = trajectory.states(effects.time_shift) if effects.time_shift else (q, qd, qdd)
    tau = inverse_torques(simulator(robot, p, effects), sq, sqd, sqdd) + stribeck_torque(effects, sqd)
    for i, g in effects.gain.items():
        tau[:, i - 1] *= 1.0 + g
    for i, o in effects.offset.items():
        tau[:, i - 1] += o
    sigma = np.broadcast_to(np.asarray(noise, dtype=float), (robot.dof,))
    if np.any(sigma < 0) or not np.all(np.isfinite(sigma)):
        raise ValueError(f"noise: {noise!r} must be finite and non-negative")
    tau = tau + sigma * np.random.default_rng(seed).standard_normal(tau.shape)
    return Measurement(t, q, qd, qdd, tau)


@dataclass(frozen=True)
class Encoder:
    """How positions are recorded: true + N(0, noise), rounded to the step of a `bits` encoder
    (2 pi / 2^bits rad), and no velocity or acceleration columns (as most arms log)."""

    noise: float = 1e-5  # rad
    bits: int = 20


def encoded(m: Measurement, encoder: Encoder, seed) -> Measurement:
    """m with positions as an encoder records them (qd, qdd kept only for checks; not written)."""
    rng = np.random.default_rng(seed)
    step = 2 * np.pi / 2 ** encoder.bits
    q = np.round((m.q + encoder.noise * rng.standard_normal(m.q.shape)) / step) * step
    return Measurement(m.t, q, m.qd, m.qdd, m.tau)


def csv_text(m: Measurement, velocities: bool = True) -> str:
    """Header t, q1..qN, qd1..qdN, qdd1..qddN, tau1..tauN (without qd, qdd unless
    `velocities`); 12 significant digits."""
    n = m.q.shape[1]
    kinds = ("q", "qd", "qdd", "tau") if velocities else ("q", "tau")
    names = ["t"] + [f"{k}{i}" for k in kinds for i in range(1, n + 1)]
    blocks = [m.t, m.q, m.qd, m.qdd, m.tau] if velocities else [m.t, m.q, m.tau]
    out = io.StringIO()
    np.savetxt(out, np.column_stack(blocks), fmt="%.12g", delimiter=",", header=",".join(names), comments="")
    return out.getvalue()


def write_csv(path, m: Measurement) -> None:
    write_file(Path(path), csv_text(m))


def read_csv(path) -> Measurement:
    """Back from write_csv (for checks)."""
    header = Path(path).read_text().split("\n", 1)[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    n = (len(header) - 1) // 4
    return Measurement(data[:, 0], data[:, 1:1 + n], data[:, 1 + n:1 + 2 * n], data[:, 1 + 2 * n:1 + 3 * n],
                       data[:, 1 + 3 * n:])
