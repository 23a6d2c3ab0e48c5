"""The catalogue of withheld-effect cases for the diagnosis benchmark, and the folder writer.

Every case simulates the LWR (examples/lwr.yaml) in MuJoCo (mujoco_measurements.py)
with effects that the nominal model does not contain, on two trajectories:

  fit      a finite Fourier excitation (dyngen.validation.excitation) within the joint limits
  holdout  the paper's Table V trajectory (cubic rest-to-rest segments)

plus Gaussian torque noise. The nominal model is the YAML's V-REP parameters made physically
consistent (`consistent_nominal`: MuJoCo refuses the published links 3 and 7). The truth of
each case is a machine-readable list of {effect, joints (1-based), values}.

`write_cases(folder)` writes, deterministically (same arguments, byte-identical files):

  truth.json            the cases, their truth, files and the laws of the effects
  params.yaml           the nominal model's link parameters (`solution:` format, for --params)
  <case>.fit.csv        t, q1..qN, qd1..qdN, qdd1..qddN, tau1..tauN
  <case>.holdout.csv
  <case>.mujoco.xml     the simulated MuJoCo model (without the sensor effects)

(one flat folder, written all at once by dyngen.atomic.write_folder).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from dyngen.atomic import write_folder
from dyngen.description import load_robot
from dyngen.extraction.report import links_yaml
from dyngen.validation.excitation import robot_excitation
from dyngen.validation.trajectory import TABLE_V_KNOTS, TABLE_V_TIMES

from .mujoco_measurements import Effects, Encoder, Trajectory, csv_text, encoded, measure, simulator_xml, tilted_gravity

ROOT = Path(__file__).resolve().parents[2]
ROBOT = ROOT / "examples" / "lwr.yaml"
NOISE = 0.05  # Nm, torque-sensor noise sigma
FIT_SECONDS = 20.0  # two periods of the 0.1 Hz excitation
FIT_SEED = 1

# A 1.5 kg payload off the flange axis: a solid cylinder (r 0.04 m, h 0.1 m) whose centre is
# 0.13 m along z7 (the LWR flange is 0.078 m from DH frame 7) and off-centre in x and y.
_R, _H, _M = 0.04, 0.1, 1.5
PAYLOAD = np.array([_M, 0.03, -0.02, 0.13,
                    _M * (3 * _R**2 + _H**2) / 12, 0.0, 0.0, _M * (3 * _R**2 + _H**2) / 12, 0.0, _M * _R**2 / 2])
TILT_AXIS = (np.cos(np.radians(30)), np.sin(np.radians(30)), 0.0)

# The coulomb law names the module's former path, kept so that case folders stay byte-identical.
LAWS = {
    "coulomb": "fc * sign(qd)  [Nm]  (MuJoCo frictionloss, sharp: see tests/oracles/mujoco_measurements.py)",
    "viscous": "fv * qd  [Nm s/rad]  (MuJoCo damping)",
    "stribeck": "sign(qd) * (fc + (fs - fc) * exp(-(qd / vs)^2))  (fc by MuJoCo frictionloss, the rest added)",
    "armature": "ia * qdd  [kg m^2]  (MuJoCo armature)",
    "offset": "measured = true + offset  [Nm]",
    "gain": "measured = (1 + gain) * true",
    "payload": "a rigid body fixed to link N: p = dynamic parameters in DH frame N (m, cx, cy, cz, Ixx, Ixy, Ixz, "
               "Iyy, Iyz, Izz; I about its CoM), s = standard parameters (m, mx, my, mz, XX, XY, XZ, YY, YZ, ZZ "
               "about the origin of frame N); joints = [N], the link it sits on",
    "tilt": "the base turned by angle_deg about the horizontal axis `axis` (base frame): gravity in the base "
            "frame = R(axis, angle)^T g",
    "time_shift": "measured tau(t) = true tau(t - dt): the torque lags the positions by dt [s]",
    "coefficients": "the simulated arm has link masses and CoM inertias scaled by 1 +- relative (signs per link: "
                    "p_true); the model has params.yaml",
    "noise": "measured += noise_sigma * N(0, 1), independent per sample and joint",
}


@dataclass(frozen=True)
class Case:
    name: str
    effects: Effects = field(default_factory=Effects)
    coefficient_error: float = 0.0  # relative error of the model's masses and inertias
    tracked: bool = False  # forward simulation under a controller (sticky friction, mujoco_tracking.py)


CASES = [
    Case("none"),
    Case("coulomb", Effects(coulomb={1: 1.0, 6: 1.0})),
    Case("viscous", Effects(viscous={1: 0.5, 6: 0.5})),
    Case("stribeck", Effects(coulomb={4: 0.8}, stribeck={4: (0.8, 0.1)})),
    Case("armature", Effects(armature={1: 0.1})),
    Case("offset", Effects(offset={5: 0.8})),
    Case("gain", Effects(gain={2: 0.05})),
    Case("payload", Effects(payload=PAYLOAD)),
    Case("tilt", Effects(tilt_deg=3.0, tilt_axis=TILT_AXIS)),
    Case("time_shift", Effects(time_shift=0.010)),
    Case("coefficients", coefficient_error=0.10),
    # two effects at once
    Case("friction_offset", Effects(coulomb={1: 1.0}, viscous={1: 0.5}, offset={5: 0.8})),
    Case("payload_coulomb", Effects(payload=PAYLOAD, coulomb={6: 1.0})),
    Case("gain_viscous", Effects(gain={2: 0.05}, viscous={6: 0.5})),
]

# Friction as real joints have it: the arm tracks its reference in a forward simulation, and
# friction (MuJoCo's stiff friction loss, a Stribeck excess through qfrc_applied) sticks at
# reversals and rests (tests/simulation/mujoco_tracking.py).
TRACKED_CASES = [
    Case("sticky", Effects(coulomb={2: 0.9, 4: 0.5}, viscous={2: 0.4}), tracked=True),
    Case("stribeck_sticky", Effects(coulomb={4: 0.6}, stribeck={4: (0.6, 0.08)}), tracked=True),
    Case("sticky_offset", Effects(coulomb={6: 0.4}, offset={1: 0.3}), tracked=True),
]

# A sensor effect beside an effect on the arm: the sensor lags or scales friction and gravity
# as it does the rest of the torque (written after the cases above, whose noise stays as it was).
COMPOSED_CASES = [
    Case("shift_coulomb", Effects(coulomb={3: 1.2}, time_shift=0.010)),
    Case("gain_tilt", Effects(gain={2: 0.06}, tilt_deg=3.0, tilt_axis=TILT_AXIS)),
    # and a tilt turns a payload's gravity as it does the arm's
    Case("payload_tilt", Effects(payload=PAYLOAD, tilt_deg=3.0, tilt_axis=TILT_AXIS)),
]

# Settings between the diagnosis's variants (Stribeck vs 0.03/0.1/0.3 rad/s, time shifts
# 1/4/16/64 ms), and a torque leading the positions: does its refinement find them?
OFF_GRID_CASES = [
    Case("stribeck_off_grid", Effects(coulomb={2: 0.6}, stribeck={2: (0.9, 0.05)})),
    Case("time_shift_off_grid", Effects(time_shift=0.007)),
    Case("time_lead", Effects(time_shift=-0.005)),
]


# ------------------------------------------------------------------ the nominal model

def consistent_nominal(p, margin: float = 0.01) -> np.ndarray:
    """p with every link's CoM inertia moved to the nearest (Euclidean, in principal moments)
    one with A + B - C >= margin * C, same principal axes; masses and CoMs unchanged. Links
    already consistent with that margin are returned unchanged."""
    P = np.array(p, dtype=float).reshape(-1, 10)
    for link in P:
        xx, xy, xz, yy, yz, zz = link[4:]
        e, V = np.linalg.eigh(np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
        deficit = e[2] * (1 + margin) - e[0] - e[1]
        if deficit > 0 or e[0] <= 0:
            # projection onto the half-space A + B - (1 + margin) C >= 0 along its normal
            n = np.array([1.0, 1.0, -(1 + margin)])
            e = e + max(deficit, 0.0) * n / (n @ n)
            I = V @ np.diag(e) @ V.T
            link[4:] = I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]
    return P.ravel()


def perturbed(p, relative: float, seed: int) -> np.ndarray:
    """Masses and CoM inertias of every link scaled by 1 +- relative (random signs); CoMs kept."""
    P = np.array(p, dtype=float).reshape(-1, 10)
    signs = np.random.default_rng(seed).choice([-1.0, 1.0], size=(P.shape[0], 2))
    P[:, 0] *= 1 + relative * signs[:, 0]
    P[:, 4:] *= (1 + relative * signs[:, 1])[:, None]
    return P.ravel()


def standard_of_body(p10) -> np.ndarray:
    """m, m c, inertia about the frame origin (parallel axis), conventions order."""
    m, c = p10[0], np.asarray(p10[1:4])
    xx, xy, xz, yy, yz, zz = p10[4:]
    I = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]) + m * (c @ c * np.eye(3) - np.outer(c, c))
    return np.array([m, *(m * c), I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]])


# ------------------------------------------------------------------ trajectories

def cubic_at(knots, times, t):
    """Table V style rest-to-rest cubics (dyngen.validation.trajectory) at any times t: the
    arm rests at the first knot before the start and at the last knot after the end."""
    knots, times, t = np.asarray(knots, float), np.asarray(times, float), np.atleast_1d(np.asarray(t, float))
    seg = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
    T = (times[seg + 1] - times[seg])[:, None]
    s = np.clip((t - times[seg]) / T[:, 0], 0.0, 1.0)[:, None]
    delta = knots[seg + 1] - knots[seg]
    moving = ((t >= times[0]) & (t <= times[-1]))[:, None]
    q = knots[seg] + delta * s * s * (3 - 2 * s)
    return q, moving * delta * 6 * s * (1 - s) / T, moving * delta * (6 - 12 * s) / T**2


def grid(duration: float, rate_hz: float) -> np.ndarray:
    return np.arange(int(np.floor(duration * rate_hz + 1e-9)) + 1) / rate_hz


def trajectories(robot, rate_hz: float, fit_seconds: float = FIT_SECONDS, seed: int = FIT_SEED):
    """{"fit": Fourier excitation, "holdout": Table V}, sampled at rate_hz. Table V is the LWR's
    (the paper's validation trajectory); another arm's holdout is a second Fourier excitation
    within its limits (seed + 1), as long as Table V."""
    excitation = robot_excitation(robot, seed)
    holdout = (lambda t: cubic_at(TABLE_V_KNOTS, TABLE_V_TIMES, t)) if uses_table_v(robot) \
        else robot_excitation(robot, seed + 1)
    return {"fit": Trajectory(grid(fit_seconds, rate_hz), excitation),
            "holdout": Trajectory(grid(TABLE_V_TIMES[-1], rate_hz), holdout)}


def uses_table_v(robot) -> bool:
    return robot.name == "lwr" and robot.dof == len(TABLE_V_KNOTS[0])


# ------------------------------------------------------------------ truth

def _joint_entry(effect, table, **value_of):
    joints = sorted(table)
    return {"effect": effect, "joints": joints,
            "values": {k: [float(f(table[j])) for j in joints] for k, f in value_of.items()}}


def truth(case: Case, robot, p_model, p_true, pi_full=None) -> list[dict]:
    """The injected effects as [{effect, joints, values}] (see LAWS for the values' meaning)."""
    e, out = case.effects, []
    coulomb_only = {j: v for j, v in e.coulomb.items() if j not in e.stribeck}
    if coulomb_only:
        out.append(_joint_entry("coulomb", coulomb_only, fc=lambda v: v))
    if e.viscous:
        out.append(_joint_entry("viscous", e.viscous, fv=lambda v: v))
    if e.stribeck:
        full = {j: (e.coulomb.get(j, 0.0), *e.stribeck[j]) for j in e.stribeck}
        out.append(_joint_entry("stribeck", full, fc=lambda v: v[0], fs=lambda v: v[0] + v[1], vs=lambda v: v[2]))
    if e.armature:
        out.append(_joint_entry("armature", e.armature, ia=lambda v: v))
    if e.offset:
        out.append(_joint_entry("offset", e.offset, offset=lambda v: v))
    if e.gain:
        out.append(_joint_entry("gain", e.gain, gain=lambda v: v))
    if e.payload is not None:
        out.append({"effect": "payload", "joints": [robot.dof],
                    "values": {"p": [float(x) for x in e.payload],
                               "s": [float(x) for x in standard_of_body(e.payload)]}})
    if e.tilt_deg:
        g0 = [float(x) for x in robot.gravity]
        out.append({"effect": "tilt", "joints": [],
                    "values": {"angle_deg": e.tilt_deg, "axis": [float(x) for x in e.tilt_axis],
                               "gravity": [float(x) for x in tilted_gravity(g0, e.tilt_deg, e.tilt_axis)]}})
    if e.time_shift:
        out.append({"effect": "time_shift", "joints": [], "values": {"dt": e.time_shift}})
    if case.coefficient_error:
        values = {"relative": case.coefficient_error, "p_true": [float(x) for x in p_true]}
        if pi_full is not None:
            values["pi_full_model"] = [float(x) for x in pi_full(p_model)]
            values["pi_full_true"] = [float(x) for x in pi_full(p_true)]
        out.append({"effect": "coefficients", "joints": [], "values": values})
    return out


# ------------------------------------------------------------------ the folder

def nominal_model(robot) -> np.ndarray:
    """consistent_nominal of the YAML's nominal parameters, rounded as params.yaml writes them
    (links_yaml, 10 digits), so the model read back is exactly the simulated arm."""
    p = consistent_nominal(np.array([v for link in robot.nominal for v in link.as_tuple()]))
    return np.array([float(f"{x:.10g}") for x in p])


def simulated_parameters(case: Case, p_model, seed: int) -> np.ndarray:
    return perturbed(p_model, case.coefficient_error, seed) if case.coefficient_error else p_model


def case_files(case: Case, index: int, robot, p_true, trajs, noise: float, seed: int,
               encoder: Encoder | None = None) -> dict[str, str]:
    """The case's CSVs and MuJoCo model; noise seeded by (seed, case index, trajectory index).
    With an encoder, positions carry its noise and steps and the files have no qd, qdd."""
    files = {f"{case.name}.mujoco.xml": simulator_xml(robot, p_true, case.effects)}
    for k, (kind, traj) in enumerate(trajs.items()):
        if case.tracked:
            from .mujoco_tracking import track

            m, _ = track(robot, p_true, p_model_of(robot), traj.t, traj.at, case.effects, noise, seed=[seed, index, k])
        else:
            m = measure(robot, p_true, traj, case.effects, noise, seed=[seed, index, k])
        if encoder is not None:
            m = encoded(m, encoder, seed=[seed, index, k, 1])
        files[f"{case.name}.{kind}.csv"] = csv_text(m, velocities=encoder is None)
    return files


def p_model_of(robot) -> np.ndarray:
    return nominal_model(robot)


def write_cases(folder, rate_hz: float = 1000.0, noise: float = NOISE, seed: int = 0, cases=CASES,
                fit_seconds: float = FIT_SECONDS, pi_full=None, robot_path=ROBOT, encoder: Encoder | None = None) -> dict:
    """Write every case (see the module doc) and return the truth document.
    pi_full: optional p -> base coefficients (e.g. dyngen.runtime's "pi_full"), recorded in the
    truth of the coefficients case."""
    robot = load_robot(robot_path)
    p_model = nominal_model(robot)
    trajs = trajectories(robot, rate_hz, fit_seconds)
    # The path in this comment is the module's former one, kept so that case folders stay byte-identical.
    files = {"params.yaml": "# The nominal model: examples/lwr.yaml's V-REP parameters, inertias of links 3 and 7 "
                            "made consistent (tests/oracles/withheld_cases.py consistent_nominal).\n"
                            f"robot: {robot.name}\nsolution:\n" + links_yaml(p_model)}
    robot_path = Path(robot_path).resolve()
    doc = {"robot": str(robot_path.relative_to(ROOT) if robot_path.is_relative_to(ROOT) else robot_path),
           "params": "params.yaml", "rate_hz": float(rate_hz), "noise_sigma": noise, "seed": seed,
           "trajectories": {"fit": {"kind": "fourier", "seed": FIT_SEED, "seconds": fit_seconds,
                                    "base_hz": 0.1, "harmonics": 5},
                            "holdout": {"kind": "table_v", "seconds": float(TABLE_V_TIMES[-1])} if uses_table_v(robot)
                            else {"kind": "fourier", "seed": FIT_SEED + 1, "seconds": float(TABLE_V_TIMES[-1]),
                                  "base_hz": 0.1, "harmonics": 5}},
           "laws": LAWS, "cases": [],
           "positions": "exact, with qd and qdd columns" if encoder is None else
           {"noise": encoder.noise, "bits": encoder.bits, "columns": "t, q, tau (no qd, qdd)"}}
    for index, case in enumerate(cases):
        p_true = simulated_parameters(case, p_model, seed)
        files.update(case_files(case, index, robot, p_true, trajs, noise, seed, encoder))
        doc["cases"].append({"name": case.name, "fit": f"{case.name}.fit.csv", "holdout": f"{case.name}.holdout.csv",
                             "noise_sigma": noise, "effects": truth(case, robot, p_model, p_true, pi_full)})
    files["truth.json"] = json.dumps(doc, indent=1) + "\n"
    write_folder(Path(folder), files)
    return doc
