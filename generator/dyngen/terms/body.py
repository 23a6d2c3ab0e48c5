"""The rigid body (its base regressor Y(q, qd, qdd); as a candidate "coefficients": errors in every
base coefficient) and a payload on the last link: its 10 standard parameters, whose torque
columns are rnea(q, qd, qdd, e_k) (Newton-Euler is linear in them)."""

from __future__ import annotations

import numpy as np

from ..parameters import PER_LINK, STANDARD_NAMES_PER_LINK, consistency_margin, dynamic_from_standard_link, inertia_array
from .term import Term, Value


class RigidBody(Term):
    """The full dynamics' base coefficients pi; as a diagnosis's candidate, errors in every one."""

    name, scope, doc = "coefficients", "arm", "the rigid body's base coefficients: Y(q, qd, qdd) pi"

    def __init__(self, parameters=()):
        self.parameters = tuple(parameters)  # the standard names of the full model's base coefficients
        self.units = ("SI",) * len(self.parameters)

    @staticmethod
    def regressor(model, q, qd, qdd):
        """(T, N, r): the compiled model's base regressor."""
        return model.batch("regressor", q, qd, qdd)

    @classmethod
    def of(cls, context):
        return cls(e["standard"] for e in context.model.manifest["coefficients"]["full"]["expressions"])

    def columns(self, context, signals, tau_model):
        return self.regressor(context.model, signals.q, signals.qd, signals.qdd)


class Payload(Term):
    """A body of positive mass, not more than the arm's, its centre within REACH of the flange frame."""

    name, scope, doc = "payload", "arm", "a payload: a body fixed to the last link (its 10 standard parameters)"
    values = tuple(Value(n, u) for n, u in zip(STANDARD_NAMES_PER_LINK, (
        "kg", "kg m", "kg m", "kg m", "kg m^2", "kg m^2", "kg m^2", "kg m^2", "kg m^2", "kg m^2")))
    REACH = 1.0  # m: the centre of mass at most this far from the flange frame
    # Its setting (m, mx, my, mz, refined to the fitted values) is the body whose gravity a tilt
    # turns with the arm's (Context.load): the product of the two enters the tilt's columns.
    refinable = shapes_others = True

    def __init__(self, max_mass: float, weight=None):
        self.max_mass = float(max_mass)  # kg: the arm's own mass; a heavier "payload" is refused
        self.weight = None if weight is None else tuple(float(x) for x in weight)  # (m, mx, my, mz) setting

    @classmethod
    def inside(cls, values, scales=None):
        m = values[0]
        return bool(0 < m < scales["arm mass"] and np.linalg.norm(values[1:4]) < cls.REACH * m)

    @staticmethod
    def regressor(model, q, qd, qdd, units) -> np.ndarray:
        """(T, N, k): Newton-Euler torques of the last link's standard parameters units[k]."""
        n = q.shape[1]
        out = np.empty(q.shape + (len(units),))
        for k, unit in enumerate(units):
            s = np.zeros(PER_LINK * n)
            s[PER_LINK * (n - 1):] = unit
            out[:, :, k] = model.batch("rnea", q, qd, qdd, s)
        return out

    @classmethod
    def of(cls, context):
        return cls(float(np.sum(np.asarray(context.p, dtype=float).reshape(-1, PER_LINK)[:, 0])))

    @property
    def setting(self):
        return np.zeros(4) if self.weight is None else np.array(self.weight)

    def implied_setting(self, values):
        return np.array(values[:4], dtype=float)

    def at(self, setting):
        return Payload(self.max_mass, setting)

    @property
    def load(self):
        return self.weight

    def range_scales(self):
        return {"arm mass": self.max_mass}

    def simplified(self, values):
        """A fitted inertia no body has: at the fitted centre, either the nearest body's inertia per kg or
        none (FixedShapePayload), whichever predicts the selection data better (the data determine m and
        m c far better than the inertia)."""
        if consistent_inertia(values):
            return None
        refusal = ("the payload's inertia about its centre of mass (not a body's; the payload keeps its fitted "
                   "centre, with the nearest body's inertia per kg or none, whichever does better on selection "
                   "data)", values[4:].tolist())
        m, c = values[0], values[1:4] / values[0]
        nearest = nearest_body_inertia(inertia_array(values[4:10]) - m * _point(c))
        return refusal, [FixedShapePayload(c, J, self.max_mass, values[:4]) for J in (nearest / m, np.zeros((3, 3)))]

    def columns(self, context, signals, tau_model):
        return self.regressor(context.model, signals.q, signals.qd, signals.qdd, np.eye(PER_LINK))

    def derived(self, robot, values, std, torque_rms):
        m = values.get("m")
        if m in (None, 0.0):
            return {}
        return {"mass_kg": m,
                "com_m": [values[k] / m if values.get(k) is not None else None for k in ("mx", "my", "mz")]}

    @classmethod
    def last_link(cls, values, variant=None):
        """Its 10 standard values, or a fixed shape's 4 (m, m c) with the variant's inertia per kg."""
        if None in values.values():
            return None
        if "XX" in values:
            return np.array(list(values.values()), dtype=float)
        m = values["m"]
        c = np.array([values[k] for k in ("mx", "my", "mz")]) / m
        I = m * (inertia_array((variant or {}).get("inertia_per_kg", [0.0] * 6)) + _point(c))
        return np.array([m, *(m * c), *(I[i, k] for i, k in _UPPER)])


class FixedShapePayload(Payload):
    """A payload of a fixed shape (centre c0, inertia J0 about it per kg), its values m and m c."""

    values = Payload.values[:4]

    def __init__(self, centre, per_kg, max_mass: float, weight=None):
        super().__init__(max_mass, weight)
        self.centre = np.asarray(centre, dtype=float)
        self.per_kg = np.asarray(per_kg, dtype=float)  # (3, 3) J0
        centre = "c0=(" + ",".join(f"{x:.4g}" for x in self.centre) + ")"
        self.label = (f"point mass at {centre}" if not self.per_kg.any() else
                      f"fixed shape at {centre}, J0=(" + ",".join(f"{self.per_kg[i, k]:.4g}" for i, k in _UPPER) + ")")

    def fixed(self):
        J = self.per_kg
        return {"centre_m": [float(x) for x in self.centre],
                "inertia_per_kg": [float(J[i, k]) for i, k in _UPPER]}  # XX, XY, XZ, YY, YZ, ZZ about the centre

    def at(self, setting):
        return FixedShapePayload(self.centre, self.per_kg, self.max_mass, setting)

    def simplified(self, values):
        return None  # always a body

    def columns(self, context, signals, tau_model):
        I = self.per_kg + _point(self.centre)  # per kg, about the frame origin
        units = [np.array([1.0, 0, 0, 0, *(I[i, k] for i, k in _UPPER)]), *np.eye(PER_LINK)[1:4]]
        return self.regressor(context.model, signals.q, signals.qd, signals.qdd, np.array(units))


_UPPER = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))  # XX, XY, XZ, YY, YZ, ZZ


def _point(c) -> np.ndarray:
    """Inertia of a unit point mass at c about the origin."""
    c = np.asarray(c, dtype=float)
    return c @ c * np.eye(3) - np.outer(c, c)


def nearest_body_inertia(I) -> np.ndarray:
    """The body inertia nearest to the symmetric I (principal moments; the nearest valid face projection)."""
    e, V = np.linalg.eigh(I)
    faces = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]], dtype=float)
    best, distance = np.zeros(3), np.inf
    for subset in range(64):
        A = faces[[k for k in range(6) if subset >> k & 1]]
        x = e - A.T @ np.linalg.lstsq(A @ A.T, A @ e, rcond=None)[0] if len(A) else e  # onto A x = 0
        if np.all(faces @ x >= -1e-15 * max(np.abs(e).max(), 1e-300)) and np.linalg.norm(x - e) < distance:
            best, distance = x, np.linalg.norm(x - e)
    return V @ np.diag(np.maximum(best, 0.0)) @ V.T


def consistent_inertia(values) -> bool:
    """Whether a payload's 10 standard values describe a body (parameters.consistency_margin)."""
    return consistency_margin(dynamic_from_standard_link(values)) >= 0.0


def armature_identifiable(model, dof: int, seed: int = 0) -> list[bool]:
    """Per joint, whether its rotor inertia is independent of the rigid body's base columns."""
    rng = np.random.default_rng(seed)
    states = 40
    q, qd, qdd = (rng.uniform(-2, 2, (states, dof)) for _ in range(3))
    Y = RigidBody.regressor(model, q, qd, qdd).reshape(states * dof, -1)
    ok = []
    for j in range(dof):
        col = np.zeros((states, dof))
        col[:, j] = qdd[:, j]
        col = col.reshape(-1)
        x, *_ = np.linalg.lstsq(Y, col, rcond=None)
        ok.append(bool(np.linalg.norm(Y @ x - col) > 1e-8 * np.linalg.norm(col)))
    return ok
