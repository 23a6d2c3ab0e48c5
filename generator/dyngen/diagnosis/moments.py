"""The least-squares design of every candidate at once, as per-joint moments: each candidate owns
slots of one parameter vector x, and for joint j (columns A_j, residual r_j) the moments
G_j = A_j^T A_j, b_j = A_j^T r_j, c_j = r_j^T r_j give the fit of any subset and its residual
|r_j - A_j x|^2 = c_j - 2 x.b_j + x.G_j x without the samples: forward selection over dozens of
candidates stays cheap."""

from __future__ import annotations

import dataclasses

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Candidate:
    effect: object  # terms.Term
    joint: int | None  # 0-based joint for scope "joint"; None for arm-wide effects
    start: int  # first slot in the global parameter vector
    size: int

    @property
    def slots(self) -> np.ndarray:
        return np.arange(self.start, self.start + self.size)

    @property
    def key(self) -> str:
        return self.effect.key + ("" if self.joint is None else f" on joint {self.joint + 1}")

    @property
    def family(self) -> tuple:
        """Variants of one effect on one joint exclude each other (e.g. Stribeck velocities)."""
        return (self.effect.name, self.joint)


@dataclass
class Moments:
    G: np.ndarray  # (N, K, K)
    b: np.ndarray  # (N, K)
    c: np.ndarray  # (N,)
    count: int  # samples (per joint)

    def mse(self, slots: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Per joint mean squared residual after subtracting the candidates' fit x (at slots)."""
        G = self.G[:, slots][:, :, slots]
        sse = self.c - 2 * self.b[:, slots] @ x + np.einsum("k,jkl,l->j", x, G, x)
        return np.maximum(sse, 0.0) / max(self.count, 1)


def split_values(chosen, x) -> list[np.ndarray]:
    """Fitted values x (in chosen order) cut into each chosen candidate's values."""
    out, offset = [], 0
    for c in chosen:
        out.append(x[offset: offset + c.size])
        offset += c.size
    return out


def candidates_of(effects, n_joints: int, sizes: dict) -> list[Candidate]:
    """sizes: effect key -> number of fitted values (known once its columns were computed)."""
    out, start = [], 0
    for effect in effects:
        k = sizes[effect.key]
        for joint in ([None] if effect.scope == "arm" else range(n_joints)):
            out.append(Candidate(effect, joint, start, k))
            start += k
    return out


def effect_columns(effects, context, segment) -> dict:
    return {e.key: columns_of(e, context, segment) for e in effects}


def columns_of(effect, context, segment, joint=None) -> np.ndarray:
    """An effect's columns on one segment, memoised per segment and setting. Switching laws
    (Term.switching) pass through the recording's filter like the torque they explain. joint: of a
    local effect, only that joint's columns (the others zero). As the chosen effects have the arm
    (as_chosen): with a time shift every other effect's columns are that much later; with a sensor
    gain the arm's effects are scaled on its joint; a tilt turns a payload's gravity (Term.reads)."""
    part = joint is not None and effect.local
    delay = 0.0 if effect.delays else context.delay
    scale = None if effect.sensor else context.scale

    def compute():
        signals, tau_model = segment.signals, segment.tau_model
        if part:
            signals, tau_model = signals.of_joint(joint), tau_model[:, joint: joint + 1]
        if delay and effect.switching:
            # A law that switches is evaluated on the delayed motion, then filtered: its step
            # then falls on the sample after the delayed reversal, as in the recording (the
            # filtered step delayed afterwards sits up to a sample off: a 12-ms lag beside 2.7 Nm
            # of static friction left 1.6 x the perfect model's residual at 200 Hz).
            late = {k: delayed(getattr(signals, k), signals.t, delay) for k in ("q", "qd", "qdd")}
            signals = dataclasses.replace(signals, **late, extra={})
            tau_model = delayed(tau_model, signals.t, delay)
        x = np.asarray(effect.columns(context, signals, tau_model), float)
        x = signals.filtered(x) if effect.switching or (signals.model_filtered and not effect.sensor) else x
        x = delayed(x, signals.t, delay) if delay and not effect.switching else x
        if part:
            out = np.zeros((x.shape[0], segment.residual.shape[1], x.shape[2]))
            out[:, joint, :] = x[:, 0, :]
            x = out
        return x * np.asarray(scale)[None, :, None] if scale is not None else x

    key = ("columns", id(segment.signals), effect.key, joint if part else None, delay, scale, effect.reads(context))
    return context.memo(key, compute)


def world(context, chosen) -> dict:
    """The Context fields the chosen set: a time shift's delay, 1 + each sensor gain (scale), a payload (load)."""
    gains = {c.joint: float(c.effect.setting) for c in chosen if c.effect.scales and c.effect.setting}
    scale = tuple(1.0 + gains.get(j, 0.0) for j in range(len(context.robot.joints))) if gains else None
    return {"delay": next((float(c.effect.setting) for c in chosen if c.effect.delays), 0.0), "scale": scale,
            "load": next((c.effect.load for c in chosen if c.effect.load is not None), None)}


def as_chosen(context, chosen):
    """The context with the arm and sensor the chosen candidates describe (world)."""
    fields = world(context, chosen)
    return context if all(getattr(context, k) == v for k, v in fields.items()) else dataclasses.replace(context, **fields)


def delayed(x: np.ndarray, t: np.ndarray, delay: float) -> np.ndarray:
    """x (T, ...) at times t - delay, linearly interpolated, held at its first value before the start."""
    at = np.clip(t - delay, t[0], t[-1])
    k = np.clip(np.searchsorted(t, at, side="right"), 1, t.size - 1)
    w = ((at - t[k - 1]) / (t[k] - t[k - 1])).reshape((-1,) + (1,) * (x.ndim - 1))
    return (1.0 - w) * x[k - 1] + w * x[k]


def joint_matrix(candidates, columns: dict, joint: int) -> tuple[np.ndarray, np.ndarray]:
    """(A_j, slots): the columns acting on `joint` and their global slots."""
    blocks, slots = [], []
    for c in candidates:
        if c.joint is None or c.joint == joint:
            blocks.append(columns[c.effect.key][:, joint, :])
            slots.append(c.slots)
    return np.concatenate(blocks, axis=1), np.concatenate(slots)


def accumulate(moments: Moments, A: np.ndarray, slots: np.ndarray, r: np.ndarray, joint: int) -> None:
    moments.G[joint][np.ix_(slots, slots)] += A.T @ A
    moments.b[joint][slots] += A.T @ r
    moments.c[joint] += r @ r


def add_segment(roles, candidates, columns: dict, segment) -> None:
    """Adds a segment's samples to each role's moments (roles: pairs of Moments and a mask (T,))."""
    residual = segment.residual
    for j in range(residual.shape[1]):
        acting = [c for c in candidates if c.joint is None or c.joint == j]
        A, slots = joint_matrix(acting, columns, j) if acting else (np.zeros((residual.shape[0], 0)), np.zeros(0, int))
        for m, mask in roles:
            if mask.any():
                accumulate(m, A[mask], slots, residual[mask, j], j)
    for m, mask in roles:
        m.count += int(mask.sum())


def empty(n_joints: int, size: int) -> Moments:
    return Moments(np.zeros((n_joints, size, size)), np.zeros((n_joints, size)), np.zeros(n_joints), 0)
