"""What every torque term states (one class per term; an instance is a diagnosis's candidate at its
settings, e.g. Coulomb(0.01)): its values and their physical range, its columns and its law.

A term is linear in its fitted values, tau_term = columns @ values, its nonlinear settings fixed
while fitted. A `pointwise` term's columns of a chunk of samples need that chunk alone (a time
shift needs the samples up to its lag before; a `switching` term's go through the recording's
low-pass, which needs the filter's overlap)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Value:
    """A fitted value or setting: name, unit, open interval (low, high) in units of `per` ("", "g", "arm mass")."""

    name: str
    unit: str
    low: float = -np.inf
    high: float = np.inf
    per: str = ""

    def inside(self, x: float, scales: dict | None = None) -> bool:
        s = 1.0 if not self.per else float((scales or {})[self.per])
        return bool((self.low == -np.inf or x > self.low * s) and (self.high == np.inf or x < self.high * s))


@dataclass(frozen=True)
class FrictionField:
    """One entry of a joint's emitted friction vector: a term's value or velocity setting (<= 0: plain sign)."""

    name: str
    kind: str  # "value" | "velocity"
    doc: str


class Term:
    """name: its identifier (reports, JSON, --effects); scope "joint" (one candidate per joint, acting
    on it) or "arm"; values, settings; doc: one line (the law); friction and c: its entries of the
    emitted friction vector and its C. As the diagnosis's candidate it answers through the plain
    defaults below (classmethods read a finding, diagnosis/record.Finding)."""

    name = ""
    scope = "joint"
    doc = ""
    values: tuple = ()
    parameters: tuple = ()  # the values' names (per joint for scope "joint")
    units: tuple = ()
    settings: tuple = ()
    pointwise = True
    switching = False  # switches with the sign of the velocity: filtered like the torque it explains
    friction: tuple = ()  # FrictionField, in the order of the vector
    label = ""  # a variant's setting, e.g. "vs=0.1"
    refinable = False  # has a nonlinear setting that refine.py searches once the term is selected
    tolerance = 0.0  # a setting refined by fixed-point iteration: steps this small (absolute) end it
    suspect = ""  # a symptom rather than a cause: why, reported with a warning
    secondary = False  # loses a near tie in the selection to any plainer term (forward_selection.py)
    ranged = False  # its columns depend on the positions the fit data cover (Context.q_range)
    extends = ""  # name of the term this one only adds to, on the same joint (selected first, dropped with it)
    simple_term = ""  # the simple model's term (simple_model.NAMES) this term is, if it is one (b, Fv)
    local = False  # scope "joint": its column on joint j depends on joint j's own motion alone
    sensor = False  # acts on how torques are measured (offset, gain, time shift), not on the arm
    delays = False  # its setting is a lag of the measured torque, which every other term's torque shares
    scales = False  # its setting is its joint's sensor gain, which scales the arm's other torques on it
    shapes_others = False  # its setting enters other terms' columns (Context: delay, scale, load)
    simulator: tuple | None = None  # (URDF/MJCF joint attribute, value name) this term is, e.g. ("damping", "Fv")

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "values" in cls.__dict__:
            cls.parameters, cls.units = tuple(v.name for v in cls.values), tuple(v.unit for v in cls.values)

    @classmethod
    def inside(cls, values, scales: dict | None = None) -> bool:
        """Whether fitted values are physical: each inside its range."""
        return all(v.inside(x, scales) for v, x in zip(cls.values, np.atleast_1d(values)))

    @classmethod
    def c(cls, v: str, f, c) -> str:
        """C of its torque on one joint: v the velocity, f(name) its fields, c the C names of sgn, exp, abs, zero."""
        raise NotImplementedError

    @classmethod
    def torque(cls, m, v, f: dict):
        """Its torque at velocity v for fields f with math module m (numpy or mpmath): the emitted C's oracle."""
        raise NotImplementedError

    # ---- as a candidate of the diagnosis

    @classmethod
    def of(cls, context) -> "Term":
        """The candidate for one diagnosis (terms that need the robot or its model read the context)."""
        return cls()

    def columns(self, context, signals, tau_model: np.ndarray) -> np.ndarray:
        """(T, N, k): the columns on a recording; scope "joint": [:, j, :] is the candidate on joint j."""
        raise NotImplementedError

    def reads(self, context) -> tuple:
        """What besides the recording its columns depend on (the memo's key): other chosen terms' settings."""
        return ()

    @property
    def load(self):
        """A payload at its setting: its (m, mx, my, mz) (Context.load)."""
        return None

    def plausible(self, values: np.ndarray) -> bool:
        """Whether fitted values can be this term at all (e.g. friction opposes motion)."""
        return self.inside(values, self.range_scales())

    def range_scales(self) -> dict:
        """What its range is relative to (Value.per), e.g. {"g": 9.81}."""
        return {}

    def refusal_beside(self, values: np.ndarray, base: np.ndarray) -> str:
        """Why fitted values cannot be this term beside those of the term it extends ("" if they can)."""
        return ""

    def simplified(self, values: np.ndarray):
        """Values possible only in part: ((refusal, its values), simpler terms, one chosen on selection data)."""
        return None

    def reshapes(self, other: "Term") -> bool:
        """Whether, on the same joint as `other`, it only reshapes it (and goes)."""
        return False

    @property
    def setting(self):
        """A refinable term's nonlinear setting (what `at` takes)."""
        return None

    def implied_setting(self, values: np.ndarray) -> float | None:
        """The setting its fitted values imply (refined by fixed-point iteration), if any."""
        return None

    def search_interval(self, values: np.ndarray, beside: tuple = ()) -> tuple[float, float] | None:
        """Where to search a setting independent of its values, given the other terms on its joint."""
        return None

    def at(self, setting: float) -> "Term":
        raise NotImplementedError

    def fixed(self) -> dict:
        """Settings of a variant that are not fitted (e.g. the Stribeck velocity)."""
        return {}

    def derived(self, robot, values: dict, std: dict, torque_rms) -> dict:
        """What a reader wants beside the values; torque_rms(): RMS torque on the fit data (per-joint terms)."""
        return {}

    @classmethod
    def warnings(cls, finding) -> list[str]:
        return []

    @classmethod
    def friction_terms(cls, values: dict, variant: dict) -> dict:
        """Entries of its joint's emitted friction vector: its values, and the velocity settings its
        variant fixes (the others are the diagnosis's sign velocity: updated_model.friction_vector)."""
        return {f.name: values[f.name] if f.kind == "value" else variant[f.name]
                for f in cls.friction if f.kind == "value" or f.name in variant}

    @classmethod
    def last_link(cls, values: dict, variant: dict | None = None) -> np.ndarray | None:
        """Standard parameters it adds to the last link (a payload), else None."""
        return None

    @property
    def key(self) -> str:
        return self.name + (f"[{self.label}]" if self.label else "")


def sign(m, v, scale):
    """sign(v) smoothed as tanh(v / scale); the plain sign when scale <= 0 (the C's sgn)."""
    return m.tanh(v / scale) if scale > 0 else m.sign(v)
