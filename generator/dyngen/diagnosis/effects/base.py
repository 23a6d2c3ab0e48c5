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
    sign_velocity: float  # rad/s (m/s): sign(qd) is smoothed as tanh(qd / sign_velocity) (diagnosis Options)
    q_range: tuple | None = None  # (low, high) per joint: the positions the fit data cover
    qd_range: tuple | None = None  # (low, high) per joint: the velocities the fit data cover
    # The arm and its torque sensor as the chosen effects have them (design.as_chosen): every
    # other effect's torque is measured `delay` s late (a time shift), and the arm's (effects
    # not of the sensor) times `scale[j]` on joint j (1 + a sensor gain; None: 1 on every
    # joint); `load`: (m, mx, my, mz) of a payload on the last link, whose gravity a tilt turns
    # with the arm's.
    delay: float = 0.0
    scale: tuple | None = None
    load: tuple | None = None
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
    parameters and units: the fitted values' names and units (per joint for scope "joint").

    What the diagnosis needs to know of an effect lives here, as attributes and methods with
    plain defaults: an effect says what it needs (a context-built effect is made by `of`), what
    follows from its values (`derived`), what the updated model takes from it (`friction_terms`,
    `simulator`, `last_link`, read from a finding (record.Finding): classmethods) and when it is reported
    with a warning (`suspect`, `warnings`)."""

    term = None  # the terms.Term it is: its name, scope, parameters, units and physical range
    name = ""
    scope = "joint"
    parameters: tuple = ()
    units: tuple = ()
    label = ""  # a variant's setting, e.g. "vs = 0.1 rad/s"
    refinable = False  # has a nonlinear setting that refine.py searches once the effect is selected
    tolerance = 0.0  # a setting refined by fixed-point iteration: steps this small (absolute) end it
    suspect = ""  # a symptom rather than a cause: why, reported with a warning
    secondary = False  # loses a near tie in the selection to any plainer effect (selection.py)
    ranged = False  # its columns depend on the positions the fit data cover (Context.q_range)
    extends = ""  # name of the effect this one only adds to, on the same joint (selected first, dropped with it)
    simple_term = ""  # the simple model's term (baseline.NAMES) this effect is, if it is one (b, Fv)
    switching = False  # switches with the sign of the velocity: its columns are filtered like the torque
    local = False  # scope "joint": its column on joint j depends on joint j's own motion alone
    sensor = False  # acts on how torques are measured (offset, gain, time shift), not on the arm
    delays = False  # its setting is a lag of the measured torque, which every other effect's torque shares
    scales = False  # its setting is its joint's sensor gain, which scales the arm's other torques on it
    shapes_others = False  # its setting enters other effects' columns (Context: delay, scale, load)
    simulator: tuple | None = None  # (URDF/MJCF joint attribute, value name) this effect is, e.g. ("damping", "Fv")

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "term" in cls.__dict__ and cls.term is not None:
            cls.name, cls.scope, cls.switching = cls.term.name, cls.term.scope, cls.term.switching
            cls.parameters, cls.units = cls.term.parameters(), cls.term.units()

    @classmethod
    def of(cls, context: Context) -> "Effect":
        """The effect for one diagnosis (effects that need the robot or its model read them here)."""
        return cls()

    def columns(self, context: Context, signals, tau_model: np.ndarray) -> np.ndarray:
        """(T, N, k): column c of joint j's residual. Scope "joint": entry [:, j, :] is the
        candidate on joint j and acts on joint j only."""
        raise NotImplementedError

    def reads(self, context: Context) -> tuple:
        """The parts of the context its columns depend on besides the recording (for the memo):
        what other chosen effects set (Context.load)."""
        return ()

    @property
    def load(self):
        """A payload at its setting: its (m, mx, my, mz) (Context.load); others None."""
        return None

    def plausible(self, values: np.ndarray) -> bool:
        """Whether fitted values can be this effect at all (e.g. friction opposes motion): inside
        its term's physical range."""
        return True if self.term is None else self.term.inside(values, self.range_scales())

    def range_scales(self) -> dict:
        """What its term's range is relative to (base.Value.per), e.g. {"g": 9.81}."""
        return {}

    def refusal_beside(self, values: np.ndarray, base: np.ndarray) -> str:
        """Why fitted values cannot be this effect beside those of the effect it extends on its
        joint (Effect.extends); "" if they can."""
        return ""

    def simplified(self, values: np.ndarray):
        """Fitted values possible only in part: (the refusal to report: {"candidate", "values"},
        simpler effects that keep the first of these values, of which the selection data take
        one); else None."""
        return None

    def reshapes(self, other: "Effect") -> bool:
        """Whether this effect, on the same joint as `other`, only reshapes it (and goes)."""
        return False

    @property
    def setting(self):
        """Refinable effects: the current nonlinear setting (what `at` takes); others None."""
        return None

    def implied_setting(self, values: np.ndarray) -> float | None:
        """Refinable effects whose fitted values imply their setting (refined by fixed-point
        iteration): that setting; others None."""
        return None

    def search_interval(self, values: np.ndarray, beside: tuple = ()) -> tuple[float, float] | None:
        """Refinable effects whose setting is independent of their values: where to search
        it (refined by scalar search), given the other effects on its joint (`beside`); others
        None."""
        return None

    def at(self, setting: float) -> "Effect":
        """Refinable effects: the same effect at another setting."""
        raise NotImplementedError

    def fixed(self) -> dict:
        """Settings of a variant that are not fitted (e.g. the Stribeck velocity)."""
        return {}

    def derived(self, robot, values: dict, std: dict, torque_rms) -> dict:
        """Quantities a reader wants next to the fitted values (None where undetermined), e.g.
        tilt angles. torque_rms(): the RMS torque of the fitted values on the fit data (per-joint
        effects)."""
        return {}

    @classmethod
    def warnings(cls, finding) -> list[str]:
        """Warnings on a selected effect's finding (record.Finding)."""
        return []

    @classmethod
    def friction_terms(cls, values: dict, variant: dict) -> dict:
        """Entries of its joint's generated <robot>_friction vector (model.FRICTION_FIELDS)."""
        return {}

    @classmethod
    def last_link(cls, values: dict, variant: dict | None = None) -> np.ndarray | None:
        """Standard parameters this effect adds to the last link (a payload; its finding's
        values and variant); else None."""
        return None

    @property
    def key(self) -> str:
        return self.name + (f"[{self.label}]" if self.label else "")
