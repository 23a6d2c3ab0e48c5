"""Synthetic "measured" data for the identification and diagnosis tests, made independently
of dyngen's effect models: rigid-body torques from Pinocchio (tests/oracles/pinocchio_arm.py,
built from the DH table), effects written here in plain numpy (sign(qd) without smoothing,
an extra Pinocchio body for a payload, a rotated gravity vector for a tilt, the analytic
trajectory evaluated at shifted times for a time shift), white sensor noise."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from oracles import pinocchio_arm

from dyngen.data import Signals


def fourier(n: int, seed: int, duration: float = 10.0, rate: float = 200.0, harmonics: int = 4,
            base: float = 0.1, amplitude: float = 0.5):
    """A finite Fourier series per joint (the classic excitation trajectory): t, and functions of
    time giving q, qd, qdd exactly."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(-1, 1, (harmonics, n)) * amplitude / np.arange(1, harmonics + 1)[:, None]
    b = rng.uniform(-1, 1, (harmonics, n)) * amplitude / np.arange(1, harmonics + 1)[:, None]
    q0 = rng.uniform(-0.8, 0.8, n)
    w = 2 * np.pi * base * np.arange(1, harmonics + 1)

    def at(t):
        t = np.asarray(t, dtype=float)[:, None, None]
        s, c = np.sin(w[None, :, None] * t), np.cos(w[None, :, None] * t)
        q = q0 + (a * s + b * c).sum(axis=1)
        qd = (w[None, :, None] * (a * c - b * s)).sum(axis=1)
        qdd = (-(w ** 2)[None, :, None] * (a * s + b * c)).sum(axis=1)
        return q, qd, qdd

    return np.arange(0.0, duration, 1.0 / rate), at


def rigid_torques(arm, p, q, qd, qdd, payload=None) -> np.ndarray:
    """Pinocchio's rnea at every sample; payload: (mass, com (3,) in the last joint frame,
    inertia 3x3 about its com), an extra body on the last joint."""
    model, data = pinocchio_arm.build(arm, p)
    if payload is not None:
        mass, com, inertia = payload
        model.appendBodyToJoint(model.njoints - 1, pin.Inertia(mass, np.asarray(com, float), np.asarray(inertia, float)),
                                pin.SE3.Identity())
        data = model.createData()
    return np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]).copy() for k in range(q.shape[0])])


def signals(name, t, q, qd, qdd, tau) -> Signals:
    return Signals(name, t, q, qd, qdd, tau, {})


def noisy(tau, sigma, seed):
    return tau + np.random.default_rng(seed).normal(0.0, sigma, tau.shape)
