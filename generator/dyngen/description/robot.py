"""The Robot value: everything one YAML file says about an arm.

Kinematic constants are exact SymPy numbers (0.4 -> 2/5, "pi/2" -> pi/2) so that the
derivation drops the zero terms of cos(pi/2) exactly. Inertial data are floats.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Optional

import sympy as sp

from ..parameters import DYNAMIC_NAMES_PER_LINK
from .dh import joint_models
from .joint_model import Rigid


@dataclass(frozen=True)
class Limits:
    lower: Optional[float] = None
    upper: Optional[float] = None
    velocity: Optional[float] = None
    acceleration: Optional[float] = None
    effort: Optional[float] = None


@dataclass(frozen=True)
class Joint:
    """One DH row. For a revolute joint q adds to theta, for a prismatic one to d."""

    type: str  # "revolute" | "prismatic"
    a: sp.Expr
    alpha: sp.Expr
    d: sp.Expr
    theta: sp.Expr
    limits: Optional[Limits] = None

    @property
    def revolute(self) -> bool:
        return self.type == "revolute"


@dataclass(frozen=True)
class LinkValues:
    """The 10 dynamic parameters of one link (or their bounds), in the canonical order."""

    m: float
    c: tuple[float, float, float]
    I: tuple[float, float, float, float, float, float]  # xx, xy, xz, yy, yz, zz

    def as_tuple(self) -> tuple[float, ...]:
        return (self.m, *self.c, *self.I)

    @staticmethod
    def from_tuple(values) -> "LinkValues":
        v = tuple(float(x) for x in values)
        assert len(v) == len(DYNAMIC_NAMES_PER_LINK)
        return LinkValues(v[0], v[1:4], v[4:10])


@dataclass(frozen=True)
class IdentifiedCoefficient:
    coefficient: str  # an expression in dynamic or standard parameter names
    value: float


@dataclass(frozen=True)
class Robot:
    name: str
    source: str  # the file it came from, for error messages
    convention: str  # "standard" | "modified"
    joints: tuple[Joint, ...]
    gravity: tuple[sp.Expr, sp.Expr, sp.Expr]
    nominal: Optional[tuple[LinkValues, ...]] = None
    lower: Optional[tuple[LinkValues, ...]] = None
    upper: Optional[tuple[LinkValues, ...]] = None
    total_mass: Optional[tuple[float, float]] = None
    identified: dict = field(default_factory=dict)  # kind -> tuple[IdentifiedCoefficient]
    extraction: dict = field(default_factory=dict)  # settings: procedure, restarts, seed, margin, identities, compare
    models: Optional[tuple] = None  # JointModels given directly (a URDF); None: built from the DH table
    snaps: tuple = ()  # description/snapping.py Snap records (a URDF's constants made exact)
    snap_effects: tuple = ()  # per snap: the largest gravity-torque change it causes (snap_effect.py)
    notes: tuple = ()  # what the reader did that the user should know (links lumped beyond the tip)
    links: tuple = ()  # the URDF link name of each moving body
    joint_names: tuple = ()  # the URDF name of each moving joint, in chain order (a bag's joint states are read by them)
    link_frames: tuple = ()  # per body: the URDF link's frame in dyngen's link frame i (a Rigid)
    urdf_file: Optional[str] = None  # the URDF read (its full path), for export/urdf_copy.py
    urdf_options: dict = field(default_factory=dict)  # base_link, tip_link, snap it was read with
    tool: Optional[Rigid] = None  # the flange frame in the last link frame (description/tool.py); None: the same

    @property
    def dof(self) -> int:
        return len(self.joints)

    @cached_property
    def joint_models(self) -> tuple:
        """One JointModel per joint (description/joint_model.py), built once from the DH table."""
        return self.models if self.models is not None else joint_models(self.convention, self.joints)

    @property
    def gravity_symbols(self) -> tuple[sp.Symbol, ...]:
        """Symbols in the gravity vector, sorted by name: extra inputs of the generated code."""
        free = set().union(*(sp.sympify(g).free_symbols for g in self.gravity))
        return tuple(sorted(free, key=lambda s: s.name))
