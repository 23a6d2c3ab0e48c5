"""A new user's trial on another arm's logs (issue 25): a UR5 in MuJoCo carrying a payload, logged
as a polling logger writes it, run through exactly the README's commands with default options.

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

    python bench/trial_other_arm.py [--out /tmp/trial_ur5] [--tree GENERATOR_DIR] [--commands-only]

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
from pathlib import Path

import mujoco
import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "generator"))  # this tree's dyngen, not an installed one

from dyngen.description import load_robot  # noqa: E402
from dyngen.export import to_mjcf  # noqa: E402

YAML = ROOT / "examples" / "ur5.yaml"
SIM_DT = 0.0005  # 2 kHz physics and control
PUBLISH_EVERY = 4  # state published every 4 steps: 500 Hz
COUNTS = 2 ** 16  # encoder counts per turn
TORQUE_NOISE = np.array([0.25, 0.25, 0.25, 0.08, 0.08, 0.08])  # Nm, 1 sigma
# The truth the commands should find (per joint): dry (sticky) friction, viscous, rotor inertia.
FRICTIONLOSS = (4.0, 4.0, 3.0, 1.2, 1.2, 1.0)  # Nm
DAMPING = (3.0, 3.0, 2.0, 0.6, 0.6, 0.5)  # Nm s / rad
ARMATURE = (0.20, 0.20, 0.10, 0.03, 0.03, 0.03)  # kg m^2
PAYLOAD_KG, PAYLOAD_Z = 1.5, 0.04  # beyond the flange, along its z
GAIN_JOINT, GAIN = 2, 0.03  # the other known effect, on the unloaded arm: joint 2's sensor reads 3 % high
KP = np.array([800.0, 1600.0, 600.0, 300.0, 300.0, 200.0])
KD = np.array([40.0, 80.0, 30.0, 8.0, 8.0, 5.0])


def nominal_vector() -> np.ndarray:
    doc = yaml.safe_load(YAML.read_text())
    return np.array([v for link in doc["parameters"]["nominal"] for v in [link["m"], *link["c"], *link["I"]]],
                    dtype=float)


def arm_xml(payload: bool) -> str:
    """The exported nominal UR5 with the friction, rotor inertia and (optionally) the payload."""
    xml = to_mjcf(load_robot(YAML), nominal_vector())
    for j in range(6):
        values = f'armature="{ARMATURE[j]!r}" damping="{DAMPING[j]!r}" frictionloss="{FRICTIONLOSS[j]!r}"'
        xml = re.sub(rf'(<joint name="joint_{j + 1}"[^>]*?)armature="0" damping="0" frictionloss="0"', rf"\1{values}",
                     xml)
    if payload:
        site = '<site name="dh_frame_6" pos="0.0 0.0 0.0823" quat="1.0 0.0 0.0 0.0"/>'
        assert site in xml
        xml = xml.replace(site, site + f'<body name="payload" pos="0 0 {0.0823 + PAYLOAD_Z!r}"><inertial pos="0 0 0" '
                          f'mass="{PAYLOAD_KG!r}" diaginertia="0.002 0.002 0.002"/></body>')
    return xml


def reference(path: Path):
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, 0], data[:, 1:7], data[:, 7:13], data[:, 13:19]


def simulate(payload: bool, ref_path: Path):
    """The robot's published states: time, true q, applied torque (before the sensors)."""
    model = mujoco.MjModel.from_xml_string(arm_xml(payload))
    model.opt.timestep = SIM_DT
    nominal = mujoco.MjModel.from_xml_string(to_mjcf(load_robot(YAML), nominal_vector()))  # the controller's model
    data, ff = mujoco.MjData(model), mujoco.MjData(nominal)
    t_ref, q_ref, qd_ref, qdd_ref = reference(ref_path)
    steps = int(round(t_ref[-1] / SIM_DT))
    data.qpos[:] = q_ref[0]
    t_sim = np.arange(steps + 1) * SIM_DT
    wanted = [np.column_stack([np.interp(t_sim, t_ref, x[:, j]) for j in range(6)]) for x in (q_ref, qd_ref, qdd_ref)]
    ts, qs, taus = [], [], []
    for k, t in enumerate(t_sim):
        qr, vr, ar = wanted[0][k], wanted[1][k], wanted[2][k]
        ff.qpos[:], ff.qvel[:], ff.qacc[:] = qr, vr, ar
        mujoco.mj_inverse(nominal, ff)
        tau = ff.qfrc_inverse + KP * (qr - data.qpos) + KD * (vr - data.qvel)
        data.qfrc_applied[:] = tau
        if k % PUBLISH_EVERY == 0:
            ts.append(t)
            qs.append(data.qpos.copy())
            taus.append(tau.copy())
        mujoco.mj_step(model, data)
    return np.array(ts), np.array(qs), np.array(taus)


def sensors(q, tau, rng):
    """A 16-bit encoder (each joint's zero at a random phase of a count) and torque noise."""
    step = 2 * np.pi / COUNTS
    phase = rng.uniform(0, 1, 6)
    q_meas = (np.floor(q / step + phase) - phase + 0.5) * step
    return q_meas, tau + rng.normal(size=tau.shape) * TORQUE_NOISE


def poll(t_state, rng):
    """The logger's rows: for each, its stamp and the index of the state it read."""
    period = 2e-3
    n = int(t_state[-1] / period)
    late = rng.exponential(0.3e-3, n)
    stalled = rng.random(n) < 0.015
    late[stalled] = rng.uniform(2e-3, 6.8e-3, stalled.sum())
    written = np.arange(n) * period + 1e-3 + late
    for k in range(1, n):  # a logger catching up after a stall writes 0.7 ms apart
        written[k] = max(written[k], written[k - 1] + 0.7e-3)
    written = written[written <= t_state[-1]]
    index = np.searchsorted(t_state, written - 0.1e-3, side="right") - 1  # the last state that arrived
    return np.round(written, 6), index


def write_csv(path: Path, t, q, tau):
    header = "t," + ",".join(f"q{j}" for j in range(1, 7)) + "," + ",".join(f"tau{j}" for j in range(1, 7))
    np.savetxt(path, np.column_stack([t, q, tau]), delimiter=",", header=header, comments="", fmt="%.9g")


def make_log(out: Path, name: str, states, gain: np.ndarray, seed: int) -> dict:
    """One log of simulated states (t, q, applied torque) through sensors (torque gain per joint)
    and the logger, cut by time into fit, select and test."""
    rng = np.random.default_rng(seed)
    t_state, q, tau = states
    q_meas, tau_meas = sensors(q, tau * gain, rng)
    stamp, index = poll(t_state, rng)
    rows_q, rows_tau = q_meas[index], tau_meas[index]
    repeated = np.r_[False, index[1:] == index[:-1]]
    steps = np.diff(stamp)
    cut = stamp[0] + np.array([0.6, 0.8]) * (stamp[-1] - stamp[0])
    pieces = {"fit": stamp < cut[0], "select": (stamp >= cut[0]) & (stamp < cut[1]), "test": stamp >= cut[1]}
    for role, rows in pieces.items():
        write_csv(out / f"{name}_{role}.csv", stamp[rows], rows_q[rows], rows_tau[rows])
    write_csv(out / f"{name}_all.csv", stamp, rows_q, rows_tau)
    return {"rows": len(stamp), "repeated %": round(100 * repeated.mean(), 2),
            "states dropped %": round(100 * (1 - len(np.unique(index)) / len(t_state)), 2),
            "step ms min/median/max": [round(1e3 * float(f), 3) for f in (steps.min(), np.median(steps), steps.max())],
            "torque RMS (test)": [round(float(x), 3) for x in np.sqrt(np.mean(rows_tau[pieces["test"]] ** 2, axis=0))]}


def run(command, out: Path, name: str, tree: Path) -> int:
    env = dict(os.environ, PYTHONPATH=str(tree))
    result = subprocess.run([sys.executable, "-m", "dyngen", *command], cwd=out, env=env, capture_output=True,
                            text=True)
    (out / f"{name}.txt").write_text(result.stdout + result.stderr)
    print(f"\n$ dyngen {' '.join(command)}   (exit {result.returncode})")
    print(result.stdout + result.stderr)
    return result.returncode


TRUTH = {"coulomb": ("Fc", FRICTIONLOSS), "viscous": ("Fv", DAMPING), "armature": ("Ia", ARMATURE)}


def expected(params: str, payload: bool, gain: bool = False) -> dict:
    """(effect, joints) -> (value name, true value). Identified links carry the payload and the
    rotor inertia of joints 1-2 (ZZ1 and link 2's inertia take them: not told apart)."""
    out = {(effect, (j + 1,)): (name, float(values[j])) for effect, (name, values) in TRUTH.items() for j in range(6)}
    if params == "identified":
        del out[("armature", (1,))], out[("armature", (2,))]
    elif payload:
        out[("payload", (1, 2, 3, 4, 5, 6))] = ("m", PAYLOAD_KG)
    if gain:
        out[("gain", (GAIN_JOINT,))] = ("k-1", GAIN)
    return out


def verdict(folder: Path, truth: dict) -> list[str]:
    """Each claimed finding against the truth (within 20 %), what was missed, what was flagged."""
    path = folder / "diagnosis.json"
    if not path.exists():
        return [f"{folder.name}: no diagnosis.json (the command failed)"]
    result = json.loads(path.read_text())
    lines, found = [], set()
    for e in result["selected"]:
        key = (e["effect"], tuple(e["joints"]))
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
    parser.add_argument("--out", default="/tmp/trial_ur5")
    parser.add_argument("--tree", default=str(ROOT / "generator"),
                        help="the dyngen tree the commands run (e.g. a patched copy); default this one's")
    parser.add_argument("--commands-only", action="store_true", help="the logs in --out are already made")
    args = parser.parse_args()
    out, tree = Path(args.out), Path(args.tree)
    out.mkdir(parents=True, exist_ok=True)
    ref = out / "excitation.csv"
    if not ref.exists():
        run(["excite", str(YAML), "-o", str(ref), "--rate", "500", "--periods", "18", "-q"], out, "excite", tree)
    if not args.commands_only:
        states = {payload: simulate(payload, ref) for payload in (True, False)}
        gain = np.ones(6)
        gain[GAIN_JOINT - 1] += GAIN
        stats = {name: make_log(out, name, states[name == "loaded"], g, seed)
                 for name, g, seed in (("loaded", np.ones(6), 1), ("unloaded", np.ones(6), 2), ("gain", gain, 3))}
        print(json.dumps(stats, indent=1))
        (out / "log_stats.json").write_text(json.dumps(stats, indent=1))
    print("truth: payload", PAYLOAD_KG, "kg; Coulomb (sticky)", FRICTIONLOSS, "viscous", DAMPING, "rotor inertia",
          ARMATURE, f"; on the gain log, joint {GAIN_JOINT}'s torque read {100 * GAIN:.0f} % high")
    identified = out / "identified.yaml"
    run(["identify", str(YAML), "--data", "loaded_fit.csv", "--select", "loaded_select.csv", "-o", str(identified)],
        out, "identify", tree)
    roles = ["--select", "loaded_select.csv", "--test", "loaded_test.csv"]
    runs = {  # folder: (arguments, expected findings)
        "diagnose_identified": (["--params", str(identified), "--data", "loaded_fit.csv", *roles],
                                expected("identified", True)),
        "diagnose_nominal": (["--params", str(YAML), "--data", "loaded_fit.csv", *roles, "--control",
                              "unloaded_fit.csv"], expected("nominal", True)),
        "diagnose_unloaded": (["--params", str(YAML), "--data", "unloaded_fit.csv", "--select", "unloaded_select.csv",
                               "--test", "unloaded_test.csv"], expected("nominal", False)),
        "diagnose_split": (["--params", str(YAML), "--data", "loaded_all.csv", "--split", "0.6,0.2,0.2"],
                           expected("nominal", True)),
        "diagnose_gain": (["--params", str(YAML), "--data", "gain_fit.csv", "--select", "gain_select.csv", "--test",
                           "gain_test.csv", "--control", "unloaded_fit.csv"], expected("nominal", False, gain=True)),
    }
    for folder, (arguments, _) in runs.items():
        shutil.rmtree(out / folder, ignore_errors=True)  # a failed command must not leave the last run's result
        run(["diagnose", str(YAML), *arguments, "--out", folder], out, folder, tree)
    print("\nagainst the truth (values within 20 %):")
    for folder, (_, truth) in runs.items():
        print("\n".join(verdict(out / folder, truth)))


if __name__ == "__main__":
    main()
