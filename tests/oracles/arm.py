"""A tiny, plain description of a serial arm, independent of the dyngen package.

Only what the oracles need: DH convention, joint table, gravity, and the nominal
dynamic parameters from the YAML schema of docs/conventions.md.
"""
from __future__ import annotations

import ast
import math
import operator
from dataclasses import dataclass

import numpy as np
import yaml

CONVENTIONS = ("standard", "modified")
JOINT_TYPES = ("revolute", "prismatic")


@dataclass(frozen=True)
class Arm:
    """convention: 'standard' (T = Rz(theta) Tz(d) Tx(a) Rx(alpha), joint i axis z(i-1))
    or 'modified' (T = Rx(alpha) Tx(a) Rz(theta) Tz(d), joint i axis z(i)).
    joints: tuple of (type, a, alpha, d, theta); a revolute joint adds q to theta,
    a prismatic joint adds q to d.  gravity: (3,) in the base frame 0."""

    convention: str
    joints: tuple
    gravity: np.ndarray

    def __post_init__(self):
        if self.convention not in CONVENTIONS:
            raise ValueError(f"unknown DH convention {self.convention!r}")
        joints = tuple(
            (str(t), float(a), float(al), float(d), float(th)) for t, a, al, d, th in self.joints
        )
        for j in joints:
            if j[0] not in JOINT_TYPES:
                raise ValueError(f"unknown joint type {j[0]!r}")
        g = np.asarray(self.gravity, dtype=float).reshape(3)
        # frozen dataclass: normalise through object.__setattr__
        object.__setattr__(self, "joints", joints)
        object.__setattr__(self, "gravity", g)

    @property
    def n(self) -> int:
        return len(self.joints)

    @classmethod
    def from_yaml(cls, path, symbols: dict | None = None) -> "Arm":
        """Read the robot YAML (docs/conventions.md). Gravity entries that are symbols
        (e.g. "g") need a value in `symbols`, e.g. {"g": 9.81}."""
        doc = _load(path)
        joints = []
        for j in doc["joints"]:
            joints.append(
                (
                    j["type"],
                    evaluate(j.get("a", 0)),
                    evaluate(j.get("alpha", 0)),
                    evaluate(j.get("d", 0)),
                    evaluate(j.get("theta", 0)),
                )
            )
        gravity = [evaluate(x, symbols) for x in doc.get("gravity", [0, 0, -9.81])]
        return cls(doc["dh"], tuple(joints), np.array(gravity, dtype=float))


def nominal_parameters(path) -> np.ndarray:
    """parameters.nominal of the YAML as the flat dynamic vector p (10N):
    per link [m, cx, cy, cz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz]."""
    doc = _load(path)
    out = []
    for link in doc["parameters"]["nominal"]:
        c = [evaluate(x) for x in link["c"]]
        inertia = [evaluate(x) for x in link["I"]]
        if len(c) != 3 or len(inertia) != 6:
            raise ValueError("nominal parameters need c: [3] and I: [6]")
        out += [evaluate(link["m"])] + c + inertia
    return np.array(out, dtype=float)


def _load(path) -> dict:
    with open(path, "r", encoding="utf-8") as f:
        return yaml.safe_load(f)


# --- a safe tiny evaluator: numbers, pi, + - * /, unary +-, parentheses --------------

_BINOPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv}
_UNOPS = {ast.UAdd: operator.pos, ast.USub: operator.neg}


def evaluate(value, symbols: dict | None = None) -> float:
    """A number, or a string such as "pi/2", "-pi/2", "2*pi/3", "(0.1 + 0.2)*2".
    Names other than pi must be given in `symbols`. Nothing else is evaluated."""
    if isinstance(value, bool):
        raise ValueError("booleans are not numbers here")
    if isinstance(value, (int, float)):
        return float(value)
    if not isinstance(value, str):
        raise ValueError(f"cannot evaluate {value!r}")
    names = {"pi": math.pi}
    names.update(symbols or {})
    tree = ast.parse(value.strip(), mode="eval")
    return float(_eval_node(tree.body, names))


def _eval_node(node, names):
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return node.value
    if isinstance(node, ast.Name) and node.id in names:
        return names[node.id]
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        return _BINOPS[type(node.op)](_eval_node(node.left, names), _eval_node(node.right, names))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNOPS:
        return _UNOPS[type(node.op)](_eval_node(node.operand, names))
    raise ValueError(f"unsupported expression element: {ast.dump(node)}")
