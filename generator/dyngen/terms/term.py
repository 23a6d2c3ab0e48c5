"""What every torque term states: its values, their physical range, its columns and its law,
and what the diagnosis needs of it as a candidate (one class per term: an instance is a
candidate at its settings, e.g. Coulomb(0.01), the class the law identify fits).

A term is a torque linear in its fitted values: tau_term = columns @ values. Its nonlinear
settings (a velocity scale, a lag) are fixed while it is fitted. Columns are computed from
samples (q, qd, qdd, t, the model's torque) with numpy; a `pointwise` term's columns of a
chunk of samples need that chunk alone, so the normal equations A^T A, A^T b of any fit that
uses it accumulate chunk by chunk (a time shift needs the samples up to its lag before; a
`switching` term's columns go through the recording's low-pass like the torque, which needs
the filter's overlap at a chunk's ends).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Value:
    """A fitted value or a setting: its name, unit, and the open interval (low, high) a
    physical one lies in (units of `per`: "" absolute, "g" the size of gravity, "arm mass")."""

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
    """One entry of a joint's friction vector (the generated <robot>_friction's f): a term's value
    (kind "value") or setting (kind "velocity": a scale, the plain sign or no term when <= 0)."""

    name: str
    kind: str  # "value" | "velocity"
    doc: str


class Term:
    """name: the term's identifier (reports, JSON, --effects); scope "joint" (one candidate per
    joint, acting on it) or "arm" (shared values); values: its fitted values (parameters and units
    their names and units); settings: its nonlinear settings; doc: one line (the law).
    `friction`: its entries of the emitted friction vector and `c`, its C on one joint.

    As a diagnosis's candidate, what it needs to know of a term lives here as attributes and
    methods with plain defaults: what it needs (a context-built term is made by `of`), what
    follows from its values (`derived`), what the updated model takes from it (`friction_terms`,
    `simulator`, `last_link`, read from a finding (diagnosis/record.Finding): classmethods) and
    when it is reported with a warning (`suspect`, `warnings`)."""

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
        """Whether fitted values are physical: each inside its range (terms whose values are
        bounded together say so here)."""
        values = np.atleast_1d(values)
        return all(v.inside(x, scales) for v, x in zip(cls.values, values))

    @classmethod
    def c(cls, v: str, f, c) -> str:
        """C expression of the term's torque on one joint: v the velocity, f(name) its fields, c
        the C names of sgn(v, e) (term.sign), exp, abs (|x|) and zero (attributes)."""
        raise NotImplementedError

    @classmethod
    def torque(cls, m, v, f: dict):
        """Its torque at velocity v for fields f, with math module m (numpy or mpmath): the same
        law as `c`, the oracle the emitted C is checked against."""
        raise NotImplementedError

    # ---- as a candidate of the diagnosis

    @classmethod
    def of(cls, context) -> "Term":
        """The candidate for one diagnosis (terms that need the robot or its model read them here)."""
        return cls()

    def columns(self, context, signals, tau_model: np.ndarray) -> np.ndarray:
        """(T, N, k): column c of joint j's residual on a recording (signals; context:
        terms/context.py). Scope "joint": entry [:, j, :] is the candidate on joint j and acts on
        joint j only."""
        raise NotImplementedError

    def reads(self, context) -> tuple:
        """The parts of the context its columns depend on besides the recording (for the memo):
        what other chosen terms set (Context.load)."""
        return ()

    @property
    def load(self):
        """A payload at its setting: its (m, mx, my, mz) (Context.load); others None."""
        return None

    def plausible(self, values: np.ndarray) -> bool:
        """Whether fitted values can be this term at all (e.g. friction opposes motion): inside
        its physical range."""
        return self.inside(values, self.range_scales())

    def range_scales(self) -> dict:
        """What its range is relative to (Value.per), e.g. {"g": 9.81}."""
        return {}

    def refusal_beside(self, values: np.ndarray, base: np.ndarray) -> str:
        """Why fitted values cannot be this term beside those of the term it extends on its
        joint (Term.extends); "" if they can."""
        return ""

    def simplified(self, values: np.ndarray):
        """Fitted values possible only in part: ((what of it is refused, its values): the refusal
        to report, simpler terms that keep the first of these values, of which the selection data
        take one); else None."""
        return None

    def reshapes(self, other: "Term") -> bool:
        """Whether this term, on the same joint as `other`, only reshapes it (and goes)."""
        return False

    @property
    def setting(self):
        """Refinable terms: the current nonlinear setting (what `at` takes); others None."""
        return None

    def implied_setting(self, values: np.ndarray) -> float | None:
        """Refinable terms whose fitted values imply their setting (refined by fixed-point
        iteration): that setting; others None."""
        return None

    def search_interval(self, values: np.ndarray, beside: tuple = ()) -> tuple[float, float] | None:
        """Refinable terms whose setting is independent of their values: where to search it
        (refined by scalar search), given the other terms on its joint (`beside`); others None."""
        return None

    def at(self, setting: float) -> "Term":
        """Refinable terms: the same term at another setting."""
        raise NotImplementedError

    def fixed(self) -> dict:
        """Settings of a variant that are not fitted (e.g. the Stribeck velocity)."""
        return {}

    def derived(self, robot, values: dict, std: dict, torque_rms) -> dict:
        """Quantities a reader wants next to the fitted values (None where undetermined), e.g.
        tilt angles. torque_rms(): the RMS torque of the fitted values on the fit data (per-joint
        terms)."""
        return {}

    @classmethod
    def warnings(cls, finding) -> list[str]:
        """Warnings on a selected term's finding (diagnosis/record.Finding)."""
        return []

    @classmethod
    def friction_terms(cls, values: dict, variant: dict) -> dict:
        """Entries of its joint's generated <robot>_friction vector (FRICTION_FIELDS)."""
        return {}

    @classmethod
    def last_link(cls, values: dict, variant: dict | None = None) -> np.ndarray | None:
        """Standard parameters this term adds to the last link (a payload; its finding's values
        and variant); else None."""
        return None

    @property
    def key(self) -> str:
        return self.name + (f"[{self.label}]" if self.label else "")


def sign(m, v, scale):
    """sign(v) smoothed as tanh(v / scale); the plain sign when scale <= 0 (the C's sgn)."""
    if scale > 0:
        return m.tanh(v / scale)
    return m.sign(v)
