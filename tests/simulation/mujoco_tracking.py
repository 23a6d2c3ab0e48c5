"""Recordings the way a real arm makes them: a forward simulation in MuJoCo of the arm
tracking a reference under a computed-torque controller, with the actuator torque recorded.

Unlike mj_inverse at prescribed states (mujoco_measurements.measure), friction here acts on
the simulated motion: with MuJoCo's stiff friction-loss settings (solreffriction "0.002 1",
solimpfriction "0.999 0.999 0.001 0.5 2") a joint sticks at every reversal until the
controller's torque exceeds Fc, so the friction torque in stick phases is anything between
-Fc and Fc, as on real joints. Laws MuJoCo lacks (the Stribeck excess) are applied through
qfrc_applied at every step.

    tau = M0(q) (qdd_ref + Kp e + Kd e') + c0(q, qd) + g0(q)     (e = q_ref - q; the nominal
                                                              model's inverse dynamics, mj_inverse)

The recorded torque is that actuator torque (the arm's true dynamics and friction are what
it moves against); sensor effects (gain, offset, noise) are added to the recording. The true
friction torque (constraint, damping and applied Stribeck) is returned beside it, for checks.
Semi-implicit Euler at STEP s, recorded at the target rate.
"""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np

from .mujoco_measurements import Effects, Measurement, simulator

STICKY_SOLREF = "0.002 1"
STICKY_SOLIMP = "0.999 0.999 0.001 0.5 2"
STEP = 0.0005  # s
BANDWIDTH_HZ = 8.0  # the controller's natural frequency (critically damped)


def _sticky_model(robot, p, effects):
    model = simulator(robot, p, effects)
    for i in effects.coulomb:
        j = model.joint(f"joint_{i}")
        j.solref[:] = [float(x) for x in STICKY_SOLREF.split()]
        j.solimp[:] = [float(x) for x in STICKY_SOLIMP.split()]
    model.opt.timestep = STEP
    return model


def _stribeck_excess(effects, qd) -> np.ndarray:
    out = np.zeros_like(qd)
    for i, (excess, vs) in effects.stribeck.items():
        out[i - 1] = -np.sign(qd[i - 1]) * excess * np.exp(-(qd[i - 1] / vs) ** 2)
    return out


def track(robot, p_true, p_nominal, t, reference, effects: Effects = Effects(), noise=0.0, seed=0):
    """(Measurement, friction (T, N)) at the sample times t (uniform); reference(times) ->
    q, qd, qdd. Time shifts are not simulated here."""
    if effects.time_shift:
        raise ValueError("tracking simulation: no time shift")
    physical = replace(effects, gain={}, offset={})
    true = _sticky_model(robot, p_true, physical)
    nominal = simulator(robot, p_nominal, Effects())
    data, ctrl = mujoco.MjData(true), mujoco.MjData(nominal)
    rate = 1.0 / float(np.median(np.diff(t)))
    every = int(round(1.0 / (rate * STEP)))
    if abs(every * STEP * rate - 1.0) > 1e-9:
        raise ValueError(f"rate {rate:g} Hz is not a whole number of {STEP:g} s steps")
    steps = (t.size - 1) * every + 1
    times = t[0] + STEP * np.arange(steps)
    q_ref, qd_ref, qdd_ref = reference(times)
    w = 2 * np.pi * BANDWIDTH_HZ
    kp, kd = w * w, 2 * w
    data.qpos[:], data.qvel[:] = q_ref[0], qd_ref[0]
    n = robot.dof
    q = np.empty((t.size, n))
    qd = np.empty((t.size, n))
    qdd = np.empty((t.size, n))
    tau = np.empty((t.size, n))
    friction = np.empty((t.size, n))
    for k in range(steps):
        ctrl.qpos[:], ctrl.qvel[:] = data.qpos, data.qvel
        ctrl.qacc[:] = qdd_ref[k] + kp * (q_ref[k] - data.qpos) + kd * (qd_ref[k] - data.qvel)
        mujoco.mj_inverse(nominal, ctrl)
        command = ctrl.qfrc_inverse.copy()
        data.qfrc_applied[:] = command + _stribeck_excess(physical, data.qvel)
        mujoco.mj_forward(true, data)
        if k % every == 0:
            s = k // every
            q[s], qd[s], qdd[s], tau[s] = data.qpos, data.qvel, data.qacc, command  # qacc: what this step does
            # friction acting on the joint: constraint (friction loss), damping, Stribeck excess
            friction[s] = -(data.qfrc_constraint + data.qfrc_passive + _stribeck_excess(physical, data.qvel))
        mujoco.mj_step(true, data)
    for i, g in effects.gain.items():
        tau[:, i - 1] *= 1.0 + g
    for i, o in effects.offset.items():
        tau[:, i - 1] += o
    sigma = np.broadcast_to(np.asarray(noise, dtype=float), (n,))
    tau = tau + sigma * np.random.default_rng(seed).standard_normal(tau.shape)
    return Measurement(np.asarray(t, float), q, qd, qdd, tau), friction
