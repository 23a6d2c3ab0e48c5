"""What every effect shares: the context it is computed in, and its interface."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Context:
    """What effects may use besides the signals: the compiled model, the robot, its link
    parameters (dynamic p and standard s) and the smoothing velocity of sign(qd)."""

    model: object  # dyngen.runtime.Compiled
    robot: object  # dyngen.description.Robot
    p: np.ndarray
    s: np.ndarray
    sign_velocity: float = 0.002  # rad/s (m/s): sign(qd) is smoothed as tanh(qd / sign_velocity)
    q_range: tuple | None = None  # (low, high) per joint: the positions the fit data cover
    qd_range: tuple | None = None  # (low, high) per joint: the velocities the fit data cover
    cache: dict = field(default_factory=dict)  # columns and shared intermediates, per recording (memo)

    def memo(self, key, compute):
        """compute() once per key for the life of one diagnosis (its recordings do not change)."""
        if key not in self.cache:
            self.cache[key] = compute()
        return self.cache[key]

    def sign(self, qd: np.ndarray) -> np.ndarray:
        return np.tanh(qd / self.sign_velocity)


class Effect:
    """name: the effect's identifier in reports and JSON; scope: "joint" or "arm";
    parameters and units: the fitted values' names and units (per joint for scope "joint")."""

    name = ""
    scope = "joint"
    parameters: tuple = ()
    units: tuple = ()
    label = ""  # a variant's setting, e.g. "vs = 0.1 rad/s"
    refinable = False  # has a nonlinear setting that refine.py searches once the effect is selected
    suspect = False  # a symptom rather than a cause: always reported with a warning
    secondary = False  # loses a near tie in the selection to any plainer effect (selection.py)
    switching = False  # switches with the sign of the velocity: its columns are filtered like the torque

    def columns(self, context: Context, signals, tau_model: np.ndarray) -> np.ndarray:
        """(T, N, k): column c of joint j's residual. Scope "joint": entry [:, j, :] is the
        candidate on joint j and acts on joint j only."""
        raise NotImplementedError

    def plausible(self, values: np.ndarray) -> bool:
        """Whether fitted values can be this effect at all (e.g. friction opposes motion)."""
        return True

    setting: float = 0.0  # refinable effects: the current nonlinear setting

    def implied_setting(self, values: np.ndarray) -> float | None:
        """Refinable effects whose fitted values imply their setting (refined by fixed-point
        iteration): that setting; others None."""
        return None

    def search_interval(self, values: np.ndarray) -> tuple[float, float] | None:
        """Refinable effects whose setting is independent of their values: where to search
        it (refined by scalar search); others None."""
        return None

    def at(self, setting: float) -> "Effect":
        """Refinable effects: the same effect at another setting."""
        raise NotImplementedError

    def fixed(self) -> dict:
        """Settings of a variant that are not fitted (e.g. the Stribeck velocity)."""
        return {}

    @property
    def key(self) -> str:
        return self.name + (f"[{self.label}]" if self.label else "")
