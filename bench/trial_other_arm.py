"""A new user's trial on another arm's logs (issue 25): a UR5 or a Franka Panda in MuJoCo carrying a
payload, logged as a polling logger writes it, run through exactly the README's commands with default options.

Nothing here comes from tests/simulation: the arm, its friction, the controller and the logger
are written below, so the trial does not share the project's own assumptions about a log.

- The arm: examples/ur5.yaml's nominal links (exported to MJCF by dyngen, which tests/test_export.py
  checks against Pinocchio), with what the YAML does not have: MuJoCo's frictionloss (dry friction
  that sticks at rest, not a tanh), viscous damping and a reflected rotor inertia on every joint,
  and the known effect, a 1.5 kg payload 4 cm beyond the flange. An unloaded run of the same arm
  is the control; a third log of the unloaded motion has the other known effect, joint 2's torque
  read 3 % high (a sensor gain).
- The motion: `dyngen excite examples/ur5.yaml --rate 500 --periods 18` (3 minutes), tracked by
  the nominal model's inverse dynamics plus PD at 2 kHz (so the arm never moves exactly along
  the reference and friction is the PD's to overcome).
- The robot publishes its state at 500 Hz: positions from a 16-bit encoder (2 pi / 65536 rad,
  each joint's zero at a random count phase), the applied torque with noise (0.25 Nm on joints
  1-3, 0.08 Nm on 4-6). A logger on its own clock polls it every 2 ms, late by an exponential
  0.3 ms and now and then stalled (up to 6.8 ms), writing its own time as the stamp: a row read
  before the next state arrived repeats the last one, a stall drops states, and the steps are
  0.7-8.8 ms.
- Fit / select / test: the log cut by time into its first 60 %, the next 20 % and the last 20 %.

`--arm panda` is the issue's own first case, a Panda logged by franka_ros (see ARMS below): examples/panda.yaml,
sticky friction and rotor inertia on every joint, a 1 kg payload (the unloaded run the control, a third log of it
with joint 4's torque read 0.6 Nm high: a sensor offset), `excite --rate 1000 --periods 9` (90 s) tracked at 2 kHz
under franka_ros's example joint impedance gains; published at 1 kHz: a 17-bit encoder's q, the robot's own qd
(its encoder's counts differenced at 2 kHz and low-passed at 100 Hz by a first-order filter, as a drive does) and
the torque with noise; polled every 1 ms by a logger that also writes qd (franka_ros's dq); cut into thirds (fit,
select, test: the last third held out). It also runs the diagnosis from the positions alone (--differentiate).

`--arm panda-arrival` is issue 25's first case as it was found not to reproduce above: the same Panda with positions
as fine as a 24-bit encoder's, logged by a logger that writes every state (5.5 % of them twice) stamped when it
arrives, its latency wandering smoothly (0.5 ms RMS, 20 Hz: a queue filling and draining), so that the stamps' error
lies at tens of Hz, below the band where the position noise is measured (docs/measured-data.md, "Stamps whose error
wanders").

    python bench/trial_other_arm.py [--arm ur5|panda|panda-arrival] [--out /tmp/trial_ARM] [--tree GENERATOR_DIR]
                                     [--commands-only] [--runs diagnose_nominal,...]

prints the log's statistics, runs `dyngen identify` and `dyngen diagnose` (defaults) and prints
what they said beside the truth. Seeds are fixed; the log is the same on every run.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import mujoco
import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "generator"))  # this tree's dyngen, not an installed one

from dyngen.description import load_robot  # noqa: E402
from dyngen.export import to_mjcf  # noqa: E402

SIM_DT = 0.0005  # 2 kHz physics and control


@dataclass(frozen=True)
class Arm:
    """One trial: the arm's truth (per joint), its robot's sensors and its logger."""
    yaml: Path
    rate: float  # Hz, the excitation's and the published states' rate
    periods: int  # of the 10-s excitation
    counts: int  # encoder counts per turn
    torque_noise: tuple  # Nm, 1 sigma
    frictionloss: tuple  # Nm: MuJoCo's dry friction, sticky at rest
    damping: tuple  # Nm s / rad
    armature: tuple  # kg m^2, reflected rotor inertia
    payload_kg: float
    flange_site: str  # the exported MJCF's site in the last body, and the flange's offset along that body's z
    flange_z: float
    effect: tuple  # the third log's known effect: (effect, joint, value name, value)
    kp: tuple
    kd: tuple
    stall_rate: float  # share of the logger's polls that stall, and for how long at most (s)
    stall_max: float
    qd_cutoff: float | None  # Hz: the robot's own qd (first-order low-pass of its encoder's differences); None: no qd
    split: tuple  # fit, select (the rest is test), shares of the log's time
    payload_z: float = 0.04  # beyond the flange, along its z
    logger: str = "polled"  # polled: poll(); arrival: arrive()


ARMS = {
    "ur5": Arm(ROOT / "examples" / "ur5.yaml", 500.0, 18, 2 ** 16, (0.25, 0.25, 0.25, 0.08, 0.08, 0.08),
               (4.0, 4.0, 3.0, 1.2, 1.2, 1.0), (3.0, 3.0, 2.0, 0.6, 0.6, 0.5), (0.20, 0.20, 0.10, 0.03, 0.03, 0.03),
               1.5, '<site name="dh_frame_6" pos="0.0 0.0 0.0823" quat="1.0 0.0 0.0 0.0"/>', 0.0823,
                ("gain", 2, "k-1", 0.03), (800.0, 1600.0, 600.0, 300.0, 300.0, 200.0),
               (40.0, 80.0, 30.0, 8.0, 8.0, 5.0), 0.015, 6.8e-3, None, (0.6, 0.8)),
    # franka_ros's joint_impedance_example_controller gains; friction of the size Gaz et al. 2019 identified.
    "panda": Arm(ROOT / "examples" / "panda.yaml", 1000.0, 9, 2 ** 17, (0.08, 0.08, 0.08, 0.08, 0.03, 0.03, 0.03),
                 (0.6, 0.8, 0.6, 0.8, 0.4, 0.3, 0.3), (0.5, 0.5, 0.4, 0.4, 0.15, 0.15, 0.1),
                 (0.10, 0.10, 0.10, 0.10, 0.05, 0.05, 0.05), 1.0, '<site name="dh_frame_7" pos="0.0 0.0 0.0" quat="1.0 0.0 0.0 0.0"/>', 0.107,
                  ("offset", 4, "b", 0.6),
                 (600.0, 600.0, 600.0, 600.0, 250.0, 150.0, 50.0), (50.0, 50.0, 50.0, 50.0, 30.0, 25.0, 15.0),
                 0.010, 7.8e-3, 100.0, (1 / 3, 2 / 3)),
}
ARMS["panda-arrival"] = replace(ARMS["panda"], counts=2 ** 24, logger="arrival")


def nominal_vector(arm: Arm) -> np.ndarray:
    doc = yaml.safe_load(arm.yaml.read_text())
    return np.array([v for link in doc["parameters"]["nominal"] for v in [link["m"], *link["c"], *link["I"]]],
                    dtype=float)


def arm_xml(arm: Arm, payload: bool) -> str:
    """The exported nominal arm with the friction, rotor inertia and (optionally) the payload."""
    xml = to_mjcf(load_robot(arm.yaml), nominal_vector(arm))
    for j in range(len(arm.kp)):
        values = (f'armature="{arm.armature[j]!r}" damping="{arm.damping[j]!r}" '
                  f'frictionloss="{arm.frictionloss[j]!r}"')
        xml = re.sub(rf'(<joint name="joint_{j + 1}"[^>]*?)armature="0" damping="0" frictionloss="0"', rf"\1{values}",
                     xml)
    if payload:
        site = arm.flange_site
        assert site in xml
        xml = xml.replace(site, site + f'<body name="payload" pos="0 0 {arm.flange_z + arm.payload_z!r}"><inertial '
                          f'pos="0 0 0" mass="{arm.payload_kg!r}" diaginertia="0.002 0.002 0.002"/></body>')
    return xml


def reference(path: Path, n: int):
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, 0], data[:, 1:1 + n], data[:, 1 + n:1 + 2 * n], data[:, 1 + 2 * n:1 + 3 * n]


def simulate(arm: Arm, payload: bool, ref_path: Path):
    """The robot's states at every physics step: time, true q, applied torque (before the sensors)."""
    n = len(arm.kp)
    model = mujoco.MjModel.from_xml_string(arm_xml(arm, payload))
    model.opt.timestep = SIM_DT
    nominal = mujoco.MjModel.from_xml_string(to_mjcf(load_robot(arm.yaml), nominal_vector(arm)))  # the controller's
    data, ff = mujoco.MjData(model), mujoco.MjData(nominal)
    t_ref, q_ref, qd_ref, qdd_ref = reference(ref_path, n)
    steps = int(round(t_ref[-1] / SIM_DT))
    data.qpos[:] = q_ref[0]
    t_sim = np.arange(steps + 1) * SIM_DT
    wanted = [np.column_stack([np.interp(t_sim, t_ref, x[:, j]) for j in range(n)]) for x in (q_ref, qd_ref, qdd_ref)]
    kp, kd = np.array(arm.kp), np.array(arm.kd)
    qs, taus = [], []
    for k in range(len(t_sim)):
        qr, vr, ar = wanted[0][k], wanted[1][k], wanted[2][k]
        ff.qpos[:], ff.qvel[:], ff.qacc[:] = qr, vr, ar
        mujoco.mj_inverse(nominal, ff)
        tau = ff.qfrc_inverse + kp * (qr - data.qpos) + kd * (vr - data.qvel)
        data.qfrc_applied[:] = tau
        qs.append(data.qpos.copy())
        taus.append(tau.copy())
        mujoco.mj_step(model, data)
    return t_sim, np.array(qs), np.array(taus)


def sensors(arm: Arm, q, tau, rng):
    """The published states (every physics step at 2 kHz, one in every 2 kHz / rate published): an encoder (each
    joint's zero at a random phase of a count), the robot's own qd where it has one, and torque noise."""
    every = int(round(1 / (SIM_DT * arm.rate)))
    step = 2 * np.pi / arm.counts
    phase = rng.uniform(0, 1, q.shape[1])
    q_meas = (np.floor(q / step + phase) - phase + 0.5) * step
    qd_meas = None
    if arm.qd_cutoff is not None:  # the drive's estimate: count differences, first-order low-pass
        raw = np.vstack([np.zeros(q.shape[1]), np.diff(q_meas, axis=0) / SIM_DT])
        alpha = 1 - np.exp(-2 * np.pi * arm.qd_cutoff * SIM_DT)
        qd_meas = np.empty_like(raw)
        qd_meas[0] = 0.0
        for k in range(1, len(raw)):
            qd_meas[k] = qd_meas[k - 1] + alpha * (raw[k] - qd_meas[k - 1])
        qd_meas = qd_meas[::every]
    tau = tau[::every]
    return q_meas[::every], qd_meas, tau + rng.normal(size=tau.shape) * np.array(arm.torque_noise)


def poll(arm: Arm, t_state, rng):
    """The logger's rows: for each, its stamp and the index of the state it read."""
    period = 1 / arm.rate
    n = int(t_state[-1] / period)
    late = rng.exponential(0.15 * period, n)
    stalled = rng.random(n) < arm.stall_rate
    late[stalled] = rng.uniform(period, arm.stall_max, stalled.sum())
    written = np.arange(n) * period + period / 2 + late
    for k in range(1, n):  # a logger catching up after a stall writes 0.7 ms apart
        written[k] = max(written[k], written[k - 1] + 0.7e-3)
    written = written[written <= t_state[-1]]
    index = np.searchsorted(t_state, written - 0.1e-3, side="right") - 1  # the last state that arrived
    return np.round(written, 6), index


def arrive(arm: Arm, t_state, rng, rms=0.5e-3, hz=20.0, base=0.5e-3, twice=0.055):
    """A logger writing every state as it arrives (a share `twice` of them again, between it and the next),
    stamped on arrival: latency `base` plus a smooth wander (white noise through a 2nd-order low-pass at `hz`,
    `rms` s), never below 0.05 ms. Returns the stamps and the index of the state each row holds."""
    from scipy import signal

    step = float(np.median(np.diff(t_state)))
    wander = signal.sosfilt(signal.butter(2, hz, fs=1 / step, output="sos"), rng.standard_normal(t_state.size + 2000))
    arrival = t_state + np.maximum(base + rms * wander[2000:] / wander[2000:].std(), 0.05e-3)
    again = rng.random(t_state.size) < twice
    again[-1] = False
    index = np.repeat(np.arange(t_state.size), 1 + again)
    stamp = arrival[index]
    second = np.r_[False, index[1:] == index[:-1]]
    k = index[second]
    stamp[second] += rng.uniform(0.2, 0.8, k.size) * (arrival[k + 1] - arrival[k])
    return np.round(np.maximum.accumulate(stamp), 7), index


def write_csv(path: Path, t, q, tau, qd=None):
    n = q.shape[1]
    names = [f"q{j}" for j in range(1, n + 1)] + [f"tau{j}" for j in range(1, n + 1)]
    columns = [t, q, tau]
    if qd is not None:  # franka_ros's dq: the header names dyngen reads (t, q*, qd*, tau*)
        names += [f"qd{j}" for j in range(1, n + 1)]
        columns.append(qd)
    np.savetxt(path, np.column_stack(columns), delimiter=",", header="t," + ",".join(names), comments="", fmt="%.9g")


def make_log(arm: Arm, out: Path, name: str, states, gain: np.ndarray, offset: np.ndarray, seed: int) -> dict:
    """One log of simulated states (t, q, applied torque) through sensors (torque gain and offset per joint)
    and the logger, cut by time into fit, select and test."""
    rng = np.random.default_rng(seed)
    t_sim, q, tau = states
    q_meas, qd_meas, tau_meas = sensors(arm, q, tau * gain + offset, rng)
    t_state = t_sim[::int(round(1 / (SIM_DT * arm.rate)))]
    stamp, index = (arrive if arm.logger == "arrival" else poll)(arm, t_state, rng)
    rows_q, rows_tau = q_meas[index], tau_meas[index]
    rows_qd = None if qd_meas is None else qd_meas[index]
    repeated = np.r_[False, index[1:] == index[:-1]]
    steps = np.diff(stamp)
    cut = stamp[0] + np.array(arm.split) * (stamp[-1] - stamp[0])
    pieces = {"fit": stamp < cut[0], "select": (stamp >= cut[0]) & (stamp < cut[1]), "test": stamp >= cut[1]}
    for role, rows in pieces.items():
        write_csv(out / f"{name}_{role}.csv", stamp[rows], rows_q[rows], rows_tau[rows],
                  None if rows_qd is None else rows_qd[rows])
    write_csv(out / f"{name}_all.csv", stamp, rows_q, rows_tau, rows_qd)
    stats = {"rows": len(stamp), "repeated %": round(100 * repeated.mean(), 2),
             "states dropped %": round(100 * (1 - len(np.unique(index)) / len(t_state)), 2),
             "step ms min/median/max": [round(1e3 * float(f), 3) for f in (steps.min(), np.median(steps), steps.max())],
             "torque RMS (test)": [round(float(x), 3) for x in np.sqrt(np.mean(rows_tau[pieces["test"]] ** 2, axis=0))]}
    if qd_meas is not None:  # the robot's qd against the true velocity (differences of the true q)
        true_qd = np.gradient(q[::int(round(1 / (SIM_DT * arm.rate)))], t_state, axis=0)
        stats["recorded qd error RMS rad/s"] = [round(float(x), 5) for x in np.sqrt(np.mean((qd_meas - true_qd) ** 2,
                                                                                            axis=0))]
    return stats


def run(command, out: Path, name: str, tree: Path) -> int:
    env = dict(os.environ, PYTHONPATH=str(tree))
    result = subprocess.run([sys.executable, "-m", "dyngen", *command], cwd=out, env=env, capture_output=True,
                            text=True)
    (out / f"{name}.txt").write_text(result.stdout + result.stderr)
    print(f"\n$ dyngen {' '.join(command)}   (exit {result.returncode})")
    print(result.stdout + result.stderr)
    return result.returncode


def expected(arm: Arm, params: str, payload: bool, effect: bool = False) -> dict:
    """(effect, joints) -> (value name, true value). Identified links carry the payload and the
    rotor inertia of joints 1-2 (ZZ1 and link 2's inertia take them: not told apart)."""
    n = len(arm.kp)
    truth = {"coulomb": ("Fc", arm.frictionloss), "viscous": ("Fv", arm.damping), "armature": ("Ia", arm.armature)}
    out = {(kind, (j + 1,)): (name, float(values[j])) for kind, (name, values) in truth.items() for j in range(n)}
    if params == "identified":
        del out[("armature", (1,))], out[("armature", (2,))]
    elif payload:
        out[("payload", tuple(range(1, n + 1)))] = ("m", arm.payload_kg)
    if effect:
        kind, joint, name, value = arm.effect
        out[(kind, (joint,))] = (name, value)
    return out


def _matched(key: tuple, truth: dict) -> tuple:
    """A payload is one finding whichever joints its torque reaches (on the Panda, not joint 7: the
    payload sits on its axis)."""
    return next((k for k in truth if k[0] == key[0] == "payload"), key)


def verdict(folder: Path, truth: dict) -> list[str]:
    """Each claimed finding against the truth (within 20 %), what was missed, what was flagged."""
    path = folder / "diagnosis.json"
    if not path.exists():
        return [f"{folder.name}: no diagnosis.json (the command failed)"]
    result = json.loads(path.read_text())
    lines, found = [], set()
    for e in result["selected"]:
        key = _matched((e["effect"], tuple(e["joints"])), truth)
        found.add(key)
        name, true = truth.get(key, (None, None))
        value = e["values"].get(name) if name else None
        flag = f" (flagged suspect: {e['suspect']})" if e.get("suspect") else ""
        if name is None:
            lines.append(f"  SPURIOUS {key[0]} on {key[1]}: {e['values']}{flag}")
        elif abs(value - true) > 0.2 * abs(true):
            lines.append(f"  WRONG VALUE {key[0]} on {key[1]}: {name} = {value:.4g}, truth {true:.4g}{flag}")
        elif flag:
            lines.append(f"  RIGHT BUT FLAGGED {key[0]} on {key[1]}: {name} = {value:.4g}, truth {true:.4g}{flag}")
    for u in result["unstable"]:
        key = (u["finding"]["effect"], tuple(u["finding"]["joints"]))
        if key in truth:
            lines.append(f"  TRUE BUT 'UNSTABLE, NOT CLAIMED' {key[0]} on {key[1]}: {u['reason']}")
    missed = [k for k in truth if k not in found and k not in
              {(u["finding"]["effect"], tuple(u["finding"]["joints"])) for u in result["unstable"]}]
    lines += [f"  MISSED {k[0]} on {k[1]}" for k in missed]
    said = ("link parameters", "control run", "cannot support")  # what the user is told about the model and data
    lines += [f"  WARNING {w}" for w in result["warnings"] if any(x in w for x in said)]
    worse = [j + 1 for j, (a, b) in enumerate(zip(result["rms_after"], result["rms_simple"])) if a > b]
    after, simple = ([round(x, 3) for x in result[key]] for key in ("rms_after", "rms_simple"))
    lines.append(f"  test RMS after {after}, simple model {simple}"
                 + (f"; WORSE than simple on {worse}" if worse else ""))
    return [f"{folder.name}: {len(result['selected'])} claimed"] + lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arm", choices=sorted(ARMS), default="ur5")
    parser.add_argument("--out", help="default /tmp/trial_ARM")
    parser.add_argument("--tree", default=str(ROOT / "generator"),
                        help="the dyngen tree the commands run (e.g. a patched copy); default this one's")
    parser.add_argument("--commands-only", action="store_true", help="the logs in --out are already made")
    parser.add_argument("--runs", help="comma-separated diagnose runs (e.g. diagnose_nominal,diagnose_positions); "
                        "identify runs only with diagnose_identified. Default: every run")
    args = parser.parse_args()
    arm = ARMS[args.arm]
    out, tree = Path(args.out or f"/tmp/trial_{args.arm}"), Path(args.tree)
    out.mkdir(parents=True, exist_ok=True)
    n = len(arm.kp)
    ref = out / "excitation.csv"
    if not ref.exists():
        run(["excite", str(arm.yaml), "-o", str(ref), "--rate", f"{arm.rate:g}", "--periods", str(arm.periods), "-q"],
            out, "excite", tree)
    kind, joint, _, value = arm.effect
    gain, offset = np.ones(n), np.zeros(n)
    (gain if kind == "gain" else offset)[joint - 1] += value
    if not args.commands_only:
        states = {payload: simulate(arm, payload, ref) for payload in (True, False)}
        stats = {name: make_log(arm, out, name, states[name == "loaded"], g, b, seed)
                 for name, g, b, seed in (("loaded", np.ones(n), np.zeros(n), 1), ("unloaded", np.ones(n), np.zeros(n), 2),
                                          (kind, gain, offset, 3))}
        print(json.dumps(stats, indent=1))
        (out / "log_stats.json").write_text(json.dumps(stats, indent=1))
    print("truth: payload", arm.payload_kg, "kg; Coulomb (sticky)", arm.frictionloss, "viscous", arm.damping,
          "rotor inertia", arm.armature, f"; on the {kind} log, joint {joint}'s torque read "
          + (f"{100 * value:.0f} % high" if kind == "gain" else f"{value:g} Nm high"))
    identified = out / "identified.yaml"
    wanted = set(args.runs.split(",")) if args.runs else None
    if wanted is None or "diagnose_identified" in wanted:
        run(["identify", str(arm.yaml), "--data", "loaded_fit.csv", "--select", "loaded_select.csv", "-o",
             str(identified)], out, "identify", tree)
    roles = ["--select", "loaded_select.csv", "--test", "loaded_test.csv"]
    split = f"{arm.split[0]:.4g},{arm.split[1] - arm.split[0]:.4g},{1 - arm.split[1]:.4g}"
    runs = {  # folder: (arguments, expected findings)
        "diagnose_identified": (["--params", str(identified), "--data", "loaded_fit.csv", *roles],
                                expected(arm, "identified", True)),
        "diagnose_nominal": (["--params", str(arm.yaml), "--data", "loaded_fit.csv", *roles, "--control",
                              "unloaded_fit.csv"], expected(arm, "nominal", True)),
        "diagnose_unloaded": (["--params", str(arm.yaml), "--data", "unloaded_fit.csv", "--select",
                               "unloaded_select.csv", "--test", "unloaded_test.csv"], expected(arm, "nominal", False)),
        "diagnose_split": (["--params", str(arm.yaml), "--data", "loaded_all.csv", "--split", split],
                           expected(arm, "nominal", True)),
        f"diagnose_{kind}": (["--params", str(arm.yaml), "--data", f"{kind}_fit.csv", "--select", f"{kind}_select.csv",
                              "--test", f"{kind}_test.csv", "--control", "unloaded_fit.csv"],
                             expected(arm, "nominal", False, effect=True)),
    }
    if arm.qd_cutoff is not None:  # the "from positions alone": the recorded qd set aside
        runs["diagnose_positions"] = (["--params", str(arm.yaml), "--data", "loaded_fit.csv", *roles,
                                       "--differentiate"], expected(arm, "nominal", True))
    runs = {k: v for k, v in runs.items() if wanted is None or k in wanted}
    for folder, (arguments, _) in runs.items():
        shutil.rmtree(out / folder, ignore_errors=True)  # a failed command must not leave the last run's result
        run(["diagnose", str(arm.yaml), *arguments, "--out", folder], out, folder, tree)
    print("\nagainst the truth (values within 20 %):")
    for folder, (_, truth) in runs.items():
        print("\n".join(verdict(out / folder, truth)))


if __name__ == "__main__":
    main()
