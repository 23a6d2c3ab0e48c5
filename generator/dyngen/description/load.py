"""Read and validate a robot YAML file (schema: docs/conventions.md).

Every problem raises InputError naming the file, the field path and what was expected,
e.g. `lwr.yaml: joints[3].alpha: expected a number or an expression of pi, got "ninety"`.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import sympy as sp

from ..errors import InputError, printable
from .extraction_options import Options as ExtractionOptions
from ..options import check_yaml, yaml_keys
from ..parameters import dynamic_symbols, standard_symbols
from ..untrusted import read_yaml
from .expressions import ExpressionError, exact_number, parse_expression, shorten
from .robot import IdentifiedCoefficient, Joint, Limits, LinkValues, Robot
from .tool import tool_frame

_TOP_KEYS = {"name", "description", "dh", "gravity", "joints", "parameters", "identified", "extraction", "tool"}
_URDF_KEYS = {"urdf", "base_link", "tip_link", "snap", "name", "description", "gravity", "parameters", "identified",
              "extraction", "limits", "tool"}
_EXTRACTION_KEYS = yaml_keys(ExtractionOptions) | {"compare"}  # every extraction option, and the compared file
_JOINT_KEYS = {"type", "a", "alpha", "d", "theta", "limits", "name"}
_LIMIT_KEYS = {"lower", "upper", "velocity", "acceleration", "effort"}
_PARAMETER_KEYS = {"nominal", "bounds", "total_mass"}
_IDENTIFIED_KINDS = ("gravity", "inertia", "full")
_C_NAME = re.compile(r"[a-z][a-z0-9_]{0,39}")  # file names are <name>_kinds.h and the like
MAX_JOINTS = 40  # snake arms and long gantries; the work is bounded by time and terms instead (docs/untrusted-input.md)
# Ranges no real serial arm leaves (SI units); outside them a value is a typo or an attack, and
# extreme magnitudes (1e308, 1e-320) would overflow or underflow the generated self-test.
MAX_LENGTH = 100.0  # DH a, d and centres of mass [m]
MIN_LENGTH = 1e-9  # a nonzero length below this is written 0
MAX_ANGLE = 100.0  # DH alpha, theta [rad]
MAX_GRAVITY = 1000.0  # [m/s^2]
MAX_MASS = 1e5  # [kg]
MAX_INERTIA = 1e5  # [kg m^2]
MAX_COEFFICIENT = 1e9  # identified coefficient values
# Names of symbols the derivation uses itself: a gravity symbol of the same name would be
# taken for them (gravity [0, m1, 0] would multiply by the mass of link 1).
_RESERVED = re.compile(r"(q|qd|qdd|s|c|x|a|b|p|m|mx|my|mz|XX|XY|XZ|YY|YZ|ZZ)\d+|c\d+[xyz]|I\d+(xx|xy|xz|yy|yz|zz)"
                       r"|pi|E|I|oo|nan|zoo|gravity|tau|[A-Z][A-Z0-9_]*_K")


def load_robot(path, **urdf_options) -> Robot:
    """A robot description: a YAML file, or a URDF (by its suffix; description/urdf.py, which
    takes urdf_options base_link, tip_link, snap)."""
    path = Path(path)
    if path.suffix.lower() in (".urdf", ".xacro"):  # a .xacro is refused there, by name (docs/urdf.md)
        from .urdf import load_urdf

        return load_urdf(path, **urdf_options)
    if urdf_options:
        raise InputError(path.name, "", f"{', '.join(sorted(urdf_options))}: options for a URDF; in a YAML that "
                         "points to one, write them next to urdf:")
    doc = read_yaml(path)
    if isinstance(doc, dict) and "urdf" in doc:
        return _Reader(printable(path.name)).urdf_robot(doc, path.parent)
    return _Reader(printable(path.name)).robot(doc)  # the name reaches comments and the terminal


load_description = load_robot  # the one entry every command calls


class _Reader:
    def __init__(self, source: str):
        self.source = source

    def fail(self, field: str, message: str):
        raise InputError(self.source, field, message)

    def mapping(self, value, field, allowed):
        if not isinstance(value, dict):
            self.fail(field or "(top level)", f"expected a mapping, got {_describe(value)}")
        for key in value:
            if key not in allowed:
                key = shorten(str(key))
                self.fail(f"{field}.{key}" if field else key,
                          f"unknown field; expected one of {', '.join(sorted(allowed))}")
        return value

    def sequence(self, value, field, length=None, at_most=None):
        if not isinstance(value, list):
            self.fail(field, f"expected a list, got {_describe(value)}")
        if at_most is not None and len(value) > at_most:
            self.fail(field, f"{len(value)} entries; at most {at_most}")
        if length is not None and len(value) != length:
            self.fail(field, f"expected {length} entries, got {len(value)}")
        return value

    def number(self, value, field, limit: float | None = None) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(field, f"expected a finite number, got {_describe(value)}")
        if limit is not None and abs(value) > limit:
            self.fail(field, f"value out of range: |{value:g}| > {limit:g}")
        return float(value)

    def exact(self, value, field, what="a number", allow_symbols=False, limit=None, smallest=0.0):
        try:
            number = exact_number(value, allow_symbols, reserved=lambda name: bool(_RESERVED.fullmatch(name)))
        except ExpressionError as err:
            self.fail(field, f"expected {what}, {err}")
        if limit is not None and not number.free_symbols:
            size = abs(float(number))
            if size > limit or 0 < size < smallest:
                self.fail(field, f"value out of range: {size:g} (expected 0 or between {smallest:g} and {limit:g})"
                          if smallest else f"value out of range: |{size:g}| > {limit:g}")
        return number

    def robot(self, doc) -> Robot:
        doc = self.mapping(doc, "", _TOP_KEYS)
        for key in ("name", "dh", "joints"):
            if key not in doc:
                self.fail(key, "missing (required)")
        name = doc["name"]
        if not isinstance(name, str) or not _C_NAME.fullmatch(name):
            self.fail("name", "expected a lowercase C identifier like lwr or ur5 (at most 40 characters), "
                      f"got {_describe(name)}")
        convention = doc["dh"]
        if convention not in ("standard", "modified"):
            self.fail("dh", f'expected "standard" or "modified", got {_describe(convention)}')
        gravity = doc.get("gravity", [0, 0, -9.81])
        gravity = tuple(
            self.exact(g, f"gravity[{k}]", "a number or a symbol name", allow_symbols=True,
                       limit=MAX_GRAVITY, smallest=1e-9)
            for k, g in enumerate(self.sequence(gravity, "gravity", 3)))
        raw_joints = self.sequence(doc["joints"], "joints", at_most=MAX_JOINTS)
        if not raw_joints:
            self.fail("joints", "expected at least one joint")
        joints = tuple(self.joint(j, f"joints[{i}]") for i, j in enumerate(raw_joints))
        n = len(joints)
        params = self.mapping(doc.get("parameters") or {}, "parameters", _PARAMETER_KEYS)
        nominal = lower = upper = None
        if "nominal" in params:
            nominal = tuple(self.link_values(v, f"parameters.nominal[{i}]")
                            for i, v in enumerate(self.sequence(params["nominal"], "parameters.nominal", n)))
        if "bounds" in params:
            pairs = [self.link_bounds(v, f"parameters.bounds[{i}]")
                     for i, v in enumerate(self.sequence(params["bounds"], "parameters.bounds", n))]
            lower = tuple(lo for lo, _ in pairs)
            upper = tuple(hi for _, hi in pairs)
        total_mass = None
        if "total_mass" in params:
            total_mass = self.interval(params["total_mass"], "parameters.total_mass", MAX_MASS)
            if total_mass[1] <= 0:
                self.fail("parameters.total_mass", f"expected a positive upper bound, got {total_mass[1]:g}")
        names = {sym.name: sym for sym in standard_symbols(n) + dynamic_symbols(n)}
        identified = {}
        ident = self.mapping(doc.get("identified") or {}, "identified", set(_IDENTIFIED_KINDS))
        for kind in _IDENTIFIED_KINDS:
            if kind in ident:
                identified[kind] = tuple(self.coefficient(c, f"identified.{kind}[{k}]", names)
                                         for k, c in enumerate(self.sequence(ident[kind], f"identified.{kind}", at_most=10 * n)))
        extraction = self.extraction(doc.get("extraction") or {}, names)
        return Robot(name=name, source=self.source, convention=convention, joints=joints, gravity=gravity,
                     nominal=nominal, lower=lower, upper=upper, total_mass=total_mass, identified=identified,
                     extraction=extraction, tool=self.tool(doc.get("tool")))

    def tool(self, value):
        """The optional flange offset (description/tool.py), in the last link frame."""
        if value is None:
            return None
        value = self.mapping(value, "tool", {"xyz", "rpy"})
        xyz = [self.exact(x, f"tool.xyz[{k}]", limit=MAX_LENGTH, smallest=MIN_LENGTH)
               for k, x in enumerate(self.sequence(value.get("xyz", [0, 0, 0]), "tool.xyz", 3))]
        rpy = [self.exact(x, f"tool.rpy[{k}]", "a number or an expression of pi", limit=MAX_ANGLE)
               for k, x in enumerate(self.sequence(value.get("rpy", [0, 0, 0]), "tool.rpy", 3))]
        return tool_frame(xyz, rpy)

    def urdf_robot(self, doc, folder: Path) -> Robot:
        """A YAML that points to a URDF (urdf:, base_link, tip_link, snap) and adds what a URDF lacks:
        gravity, parameter bounds, identified coefficients, extraction settings."""
        from dataclasses import replace

        from .urdf import load_urdf

        doc = self.mapping(doc, "", _URDF_KEYS)
        target = doc["urdf"]
        if (not isinstance(target, str) or not target or len(target) > 255 or Path(target).is_absolute()
                or ".." in Path(target).parts or "\0" in target):
            self.fail("urdf", f"expected the name of a URDF in the description's folder, got {_describe(target)}")
        options = {}
        for key in ("base_link", "tip_link"):
            if key in doc:
                if not isinstance(doc[key], str) or not doc[key]:
                    self.fail(key, f"expected a link name, got {_describe(doc[key])}")
                options[key] = doc[key]
        if "snap" in doc:
            if not isinstance(doc["snap"], bool):
                self.fail("snap", f"expected true or false, got {_describe(doc['snap'])}")
            options["snap"] = doc["snap"]
        robot = load_urdf(folder / target, **options)
        changes = {"source": self.source}
        if "name" in doc:
            if not isinstance(doc["name"], str) or not _C_NAME.fullmatch(doc["name"]):
                self.fail("name", f"expected a lowercase C identifier, got {_describe(doc['name'])}")
            changes["name"] = doc["name"]
        if "gravity" in doc:
            changes["gravity"] = tuple(
                self.exact(g, f"gravity[{k}]", "a number or a symbol name", allow_symbols=True,
                           limit=MAX_GRAVITY, smallest=1e-9)
                for k, g in enumerate(self.sequence(doc["gravity"], "gravity", 3)))
        n = robot.dof
        params = self.mapping(doc.get("parameters") or {}, "parameters", _PARAMETER_KEYS)
        if "nominal" in params:
            changes["nominal"] = tuple(self.link_values(v, f"parameters.nominal[{i}]")
                                       for i, v in enumerate(self.sequence(params["nominal"], "parameters.nominal", n)))
        if "bounds" in params:
            pairs = [self.link_bounds(v, f"parameters.bounds[{i}]")
                     for i, v in enumerate(self.sequence(params["bounds"], "parameters.bounds", n))]
            changes["lower"], changes["upper"] = tuple(lo for lo, _ in pairs), tuple(hi for _, hi in pairs)
        if "total_mass" in params:
            changes["total_mass"] = self.interval(params["total_mass"], "parameters.total_mass", MAX_MASS)
        names = {sym.name: sym for sym in standard_symbols(n) + dynamic_symbols(n)}
        ident = self.mapping(doc.get("identified") or {}, "identified", set(_IDENTIFIED_KINDS))
        changes["identified"] = {kind: tuple(self.coefficient(c, f"identified.{kind}[{k}]", names)
                                             for k, c in enumerate(self.sequence(ident[kind], f"identified.{kind}")))
                                 for kind in _IDENTIFIED_KINDS if kind in ident}
        changes["extraction"] = self.extraction(doc.get("extraction") or {}, names)
        if "tool" in doc:  # given in the URDF tip link's frame: moved into dyngen's last link frame
            tool = self.tool(doc["tool"])
            changes["tool"] = robot.link_frames[-1] * tool if robot.link_frames else tool
        if "limits" in doc:  # per joint, in chain order: what excite needs beyond the URDF's
            raw = self.sequence(doc["limits"], "limits", n)
            joints = []
            for i, (joint, value) in enumerate(zip(robot.joints, raw)):
                limits = self.joint({"type": joint.type, "limits": value}, f"limits[{i}]").limits
                merged = {k: getattr(limits, k) if getattr(limits, k) is not None else getattr(joint.limits, k)
                          for k in ("lower", "upper", "velocity", "acceleration", "effort")}
                joints.append(replace(joint, limits=Limits(**merged)))
            changes["joints"] = tuple(joints)
        return replace(robot, **changes)

    def extraction(self, value, names) -> dict:
        value = dict(self.mapping(value, "extraction", _EXTRACTION_KEYS))
        value.update(check_yaml(ExtractionOptions, value, self.fail, "extraction"))
        if "identities" in value:
            ids = self.sequence(value["identities"], "extraction.identities", at_most=10 * len(names))
            for k, text in enumerate(ids):
                field = f"extraction.identities[{k}]"
                if not isinstance(text, str) or text.count("=") != 1:
                    self.fail(field, f'expected "expression = expression", got {_describe(text)}')
                for side in text.split("="):
                    self.expression(side, field, names)
            value["identities"] = tuple(ids)
        if "compare" in value:
            compare = value["compare"]
            # A description from someone else must not make dyngen read files outside its folder.
            if (not isinstance(compare, str) or not compare or len(compare) > 255 or Path(compare).is_absolute()
                    or ".." in Path(compare).parts or "\0" in compare):
                self.fail("extraction.compare", "expected the name of a file in the description's folder, got "
                          f"{_describe(compare)}")
        return value

    def joint(self, value, field) -> Joint:
        value = self.mapping(value, field, _JOINT_KEYS)
        kind = value.get("type")
        if kind not in ("revolute", "prismatic"):
            self.fail(f"{field}.type", f'unknown joint type; expected "revolute" or "prismatic", got {_describe(kind)}')
        numbers = {}
        for key in ("a", "alpha", "d", "theta"):
            angle = key in ("alpha", "theta")
            what = "a number or an expression of pi" if angle else "a number"
            numbers[key] = self.exact(value.get(key, 0), f"{field}.{key}", what,
                                      limit=MAX_ANGLE if angle else MAX_LENGTH, smallest=0.0 if angle else MIN_LENGTH)
        limits = None
        if "limits" in value:
            raw = self.mapping(value["limits"], f"{field}.limits", _LIMIT_KEYS)
            limits = Limits(**{k: self.number(v, f"{field}.limits.{k}", 1e6) for k, v in raw.items()})
            if limits.lower is not None and limits.upper is not None and limits.lower > limits.upper:
                self.fail(f"{field}.limits", f"lower {limits.lower} > upper {limits.upper}")
            for key in ("velocity", "acceleration", "effort"):
                if getattr(limits, key) is not None and getattr(limits, key) <= 0:
                    self.fail(f"{field}.limits.{key}", f"expected a positive number, got {getattr(limits, key)!r}")
        return Joint(type=kind, limits=limits, **numbers)

    def link_values(self, value, field) -> LinkValues:
        value = self.mapping(value, field, {"m", "c", "I"})
        for key in ("m", "c", "I"):
            if key not in value:
                self.fail(f"{field}.{key}", "missing (required)")
        m = self.number(value["m"], f"{field}.m", MAX_MASS)
        if m <= 0:
            self.fail(f"{field}.m", f"expected a positive mass, got {m:g}")
        c = tuple(self.number(x, f"{field}.c[{k}]", MAX_LENGTH)
                  for k, x in enumerate(self.sequence(value["c"], f"{field}.c", 3)))
        inertia = tuple(self.number(x, f"{field}.I[{k}]", MAX_INERTIA)
                        for k, x in enumerate(self.sequence(value["I"], f"{field}.I", 6)))
        return LinkValues(m, c, inertia)

    def interval(self, value, field, limit) -> tuple[float, float]:
        lo, hi = (self.number(x, f"{field}[{k}]", limit) for k, x in enumerate(self.sequence(value, field, 2)))
        if lo > hi:
            self.fail(field, f"LB > UB ({lo!r} > {hi!r})")
        return lo, hi

    def link_bounds(self, value, field) -> tuple[LinkValues, LinkValues]:
        value = self.mapping(value, field, {"m", "c", "I"})
        for key in ("m", "c", "I"):
            if key not in value:
                self.fail(f"{field}.{key}", "missing (required)")
        m = self.interval(value["m"], f"{field}.m", MAX_MASS)
        if m[0] < 0 or m[1] <= 0:
            self.fail(f"{field}.m", f"a mass cannot be negative: expected 0 <= LB <= UB with UB > 0, got "
                      f"[{m[0]:g}, {m[1]:g}]")
        c = [self.interval(x, f"{field}.c[{k}]", MAX_LENGTH)
             for k, x in enumerate(self.sequence(value["c"], f"{field}.c", 3))]
        inertia = [self.interval(x, f"{field}.I[{k}]", MAX_INERTIA)
                   for k, x in enumerate(self.sequence(value["I"], f"{field}.I", 6))]
        pairs = [m, *c, *inertia]
        return LinkValues.from_tuple([lo for lo, _ in pairs]), LinkValues.from_tuple([hi for _, hi in pairs])

    def coefficient(self, value, field, names) -> IdentifiedCoefficient:
        value = self.mapping(value, field, {"coefficient", "value"})
        expr = value.get("coefficient")
        if not isinstance(expr, str) or not expr.strip():
            self.fail(f"{field}.coefficient", f"expected an expression string like \"c7y*m7\", got {_describe(expr)}")
        self.expression(expr, f"{field}.coefficient", names)
        return IdentifiedCoefficient(expr, self.number(value.get("value"), f"{field}.value", MAX_COEFFICIENT))

    def expression(self, text, field, names) -> sp.Expr:
        """A parameter expression, checked by the whitelisting parser (nothing in it runs)."""
        try:
            return parse_expression(text, names)
        except ExpressionError as err:
            self.fail(field, f"expected an expression of parameter names, {err}")


def _describe(value) -> str:
    if isinstance(value, str):
        return f'"{shorten(value)}"'
    if value is None:
        return "nothing"
    if isinstance(value, (dict, list)):
        return f"a {'mapping' if isinstance(value, dict) else 'list'}"
    return repr(value)
