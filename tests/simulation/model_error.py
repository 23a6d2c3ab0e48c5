"""The issue-25 case of a model whose link parameters are off: the LWR in MuJoCo with every
link's mass and CoM inertia off by up to `relative` (uniform, seeded, per link), Coulomb and
viscous friction and rotor inertia on every joint, 0.05 Nm torque noise, positions from a 20-bit
encoder. The model (params.yaml) is the YAML's nominal parameters made consistent
(withheld_cases.nominal_model); the truth is returned, not written.

    truth = write(folder, rate_hz=500.0)

writes params.yaml, fit.csv (the Fourier excitation), select.csv (a second excitation, seed + 1)
and test.csv (the paper's Table V): three trajectories, one per role.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from dyngen.description import load_robot
from dyngen.extraction.report import links_yaml
from dyngen.validation.excitation import robot_excitation

from .mujoco_measurements import Effects, Encoder, Trajectory, csv_text, encoded, measure
from .withheld_cases import FIT_SECONDS, FIT_SEED, NOISE, ROBOT, grid, nominal_model, trajectories

# per joint: Coulomb Fc [Nm], viscous Fv [Nm s/rad], rotor inertia Ia [kg m^2] (joint 1's is part
# of link 1's inertia about its axis, so none there)
FRICTION = {
    "coulomb": {1: 0.9, 2: 0.8, 3: 0.5, 4: 0.5, 5: 0.3, 6: 0.2, 7: 0.1},
    "viscous": {1: 0.5, 2: 0.5, 3: 0.3, 4: 0.3, 5: 0.2, 6: 0.1, 7: 0.05},
    "armature": {2: 0.05, 3: 0.03, 4: 0.03, 5: 0.01, 6: 0.01, 7: 0.005},
}


def off(p, relative: float, seed: int) -> np.ndarray:
    """Each link's mass and CoM inertia scaled by its own 1 + u, u uniform in [-relative, relative]."""
    P = np.array(p, dtype=float).reshape(-1, 10)
    u = np.random.default_rng(seed).uniform(-relative, relative, size=(P.shape[0], 2))
    P[:, 0] *= 1 + u[:, 0]
    P[:, 4:] *= (1 + u[:, 1])[:, None]
    return P.ravel()


def effects() -> Effects:
    return Effects(coulomb=dict(FRICTION["coulomb"]), viscous=dict(FRICTION["viscous"]),
                   armature=dict(FRICTION["armature"]))


def write(folder, rate_hz: float = 500.0, relative: float = 0.15, seed: int = 0, payload=None,
          tracked: bool = True) -> dict:
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    robot = load_robot(ROBOT)
    p_model = nominal_model(robot)
    p_true = off(p_model, relative, seed)
    trajs = trajectories(robot, rate_hz)
    trajs = {"fit": trajs["fit"], "select": Trajectory(grid(FIT_SECONDS, rate_hz), robot_excitation(robot, FIT_SEED + 1)),
             "test": trajs["holdout"]}
    e = effects()
    if payload is not None:
        from dataclasses import replace

        e = replace(e, payload=payload)
    (folder / "params.yaml").write_text(f"robot: {robot.name}\nsolution:\n" + links_yaml(p_model))
    for k, (role, traj) in enumerate(trajs.items()):
        if tracked:  # friction sticks at reversals (mujoco_tracking.py), as on real joints
            from .mujoco_tracking import track

            m, _ = track(robot, p_true, p_model, traj.t, traj.at, e, NOISE, seed=[seed, 25, k])
        else:
            m = measure(robot, p_true, traj, e, NOISE, seed=[seed, 25, k])
        m = encoded(m, Encoder(), seed=[seed, 25, k, 1])
        (folder / f"{role}.csv").write_text(csv_text(m, velocities=False))
    return {"p_true": p_true, "p_model": p_model, "friction": FRICTION}
