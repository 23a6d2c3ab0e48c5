"""Read and validate a robot YAML file (schema: docs/conventions.md).

Every problem raises InputError naming the file, the field path and what was expected,
e.g. `lwr.yaml: joints[3].alpha: expected a number or an expression of pi, got "ninety"`.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import yaml

from ..errors import InputError
from .expressions import ExpressionError, exact_number
from .robot import IdentifiedCoefficient, Joint, Limits, LinkValues, Robot

_TOP_KEYS = {"name", "description", "dh", "gravity", "joints", "parameters", "identified", "extraction"}
_EXTRACTION_KEYS = {"procedure", "restarts", "seed", "margin", "identities", "compare"}
_JOINT_KEYS = {"type", "a", "alpha", "d", "theta", "limits", "name"}
_LIMIT_KEYS = {"lower", "upper", "velocity", "acceleration", "effort"}
_PARAMETER_KEYS = {"nominal", "bounds", "total_mass"}
_IDENTIFIED_KINDS = ("gravity", "inertia", "full")
_C_NAME = re.compile(r"^[a-z][a-z0-9_]*$")


def load_robot(path) -> Robot:
    path = Path(path)
    source = path.name
    try:
        text = path.read_text()
    except OSError as err:
        raise InputError(str(path), "", f"cannot read the file ({err.strerror})") from None
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise InputError(source, where, f"malformed YAML: {problem}") from None
    return _Reader(source).robot(doc)


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
                self.fail(f"{field}.{key}" if field else str(key),
                          f"unknown field; expected one of {', '.join(sorted(allowed))}")
        return value

    def sequence(self, value, field, length=None):
        if not isinstance(value, list):
            self.fail(field, f"expected a list, got {_describe(value)}")
        if length is not None and len(value) != length:
            self.fail(field, f"expected {length} entries, got {len(value)}")
        return value

    def number(self, value, field) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(field, f"expected a finite number, got {_describe(value)}")
        return float(value)

    def exact(self, value, field, what="a number", allow_symbols=False):
        try:
            return exact_number(value, allow_symbols)
        except ExpressionError as err:
            self.fail(field, f"expected {what}, {err}")

    def robot(self, doc) -> Robot:
        doc = self.mapping(doc, "", _TOP_KEYS)
        for key in ("name", "dh", "joints"):
            if key not in doc:
                self.fail(key, "missing (required)")
        name = doc["name"]
        if not isinstance(name, str) or not _C_NAME.match(name):
            self.fail("name", f"expected a lowercase C identifier like lwr or ur5, got {_describe(name)}")
        convention = doc["dh"]
        if convention not in ("standard", "modified"):
            self.fail("dh", f'expected "standard" or "modified", got {_describe(convention)}')
        gravity = doc.get("gravity", [0, 0, -9.81])
        gravity = tuple(
            self.exact(g, f"gravity[{k}]", "a number or a symbol name", allow_symbols=True)
            for k, g in enumerate(self.sequence(gravity, "gravity", 3)))
        joints = tuple(self.joint(j, f"joints[{i}]") for i, j in enumerate(self.sequence(doc["joints"], "joints")))
        if not joints:
            self.fail("joints", "expected at least one joint")
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
            total_mass = self.interval(params["total_mass"], "parameters.total_mass")
        identified = {}
        ident = self.mapping(doc.get("identified") or {}, "identified", set(_IDENTIFIED_KINDS))
        for kind in _IDENTIFIED_KINDS:
            if kind in ident:
                identified[kind] = tuple(self.coefficient(c, f"identified.{kind}[{k}]")
                                         for k, c in enumerate(self.sequence(ident[kind], f"identified.{kind}")))
        extraction = self.extraction(doc.get("extraction") or {})
        return Robot(name=name, source=self.source, convention=convention, joints=joints, gravity=gravity,
                     nominal=nominal, lower=lower, upper=upper, total_mass=total_mass, identified=identified,
                     extraction=extraction)

    def extraction(self, value) -> dict:
        value = dict(self.mapping(value, "extraction", _EXTRACTION_KEYS))
        if "procedure" in value and value["procedure"] not in ("joint", "two-stage"):
            self.fail("extraction.procedure", f'expected "joint" or "two-stage", got {_describe(value["procedure"])}')
        for key in ("restarts", "seed"):
            if key in value and (not isinstance(value[key], int) or isinstance(value[key], bool) or value[key] < 1):
                self.fail(f"extraction.{key}", f"expected a positive whole number, got {_describe(value[key])}")
        if "margin" in value:
            value["margin"] = self.number(value["margin"], "extraction.margin")
        if "identities" in value:
            ids = self.sequence(value["identities"], "extraction.identities")
            for k, text in enumerate(ids):
                if not isinstance(text, str) or text.count("=") != 1:
                    self.fail(f"extraction.identities[{k}]", f'expected "expression = expression", got {_describe(text)}')
            value["identities"] = tuple(ids)
        if "compare" in value and not isinstance(value["compare"], str):
            self.fail("extraction.compare", f"expected a file name, got {_describe(value['compare'])}")
        return value

    def joint(self, value, field) -> Joint:
        value = self.mapping(value, field, _JOINT_KEYS)
        kind = value.get("type")
        if kind not in ("revolute", "prismatic"):
            self.fail(f"{field}.type", f'unknown joint type; expected "revolute" or "prismatic", got {_describe(kind)}')
        numbers = {}
        for key in ("a", "alpha", "d", "theta"):
            what = "a number or an expression of pi" if key in ("alpha", "theta") else "a number"
            numbers[key] = self.exact(value.get(key, 0), f"{field}.{key}", what)
        limits = None
        if "limits" in value:
            raw = self.mapping(value["limits"], f"{field}.limits", _LIMIT_KEYS)
            limits = Limits(**{k: self.number(v, f"{field}.limits.{k}") for k, v in raw.items()})
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
        m = self.number(value["m"], f"{field}.m")
        c = tuple(self.number(x, f"{field}.c[{k}]") for k, x in enumerate(self.sequence(value["c"], f"{field}.c", 3)))
        inertia = tuple(self.number(x, f"{field}.I[{k}]")
                        for k, x in enumerate(self.sequence(value["I"], f"{field}.I", 6)))
        return LinkValues(m, c, inertia)

    def interval(self, value, field) -> tuple[float, float]:
        lo, hi = (self.number(x, f"{field}[{k}]") for k, x in enumerate(self.sequence(value, field, 2)))
        if lo > hi:
            self.fail(field, f"LB > UB ({lo} > {hi})")
        return lo, hi

    def link_bounds(self, value, field) -> tuple[LinkValues, LinkValues]:
        value = self.mapping(value, field, {"m", "c", "I"})
        for key in ("m", "c", "I"):
            if key not in value:
                self.fail(f"{field}.{key}", "missing (required)")
        m = self.interval(value["m"], f"{field}.m")
        c = [self.interval(x, f"{field}.c[{k}]") for k, x in enumerate(self.sequence(value["c"], f"{field}.c", 3))]
        inertia = [self.interval(x, f"{field}.I[{k}]")
                   for k, x in enumerate(self.sequence(value["I"], f"{field}.I", 6))]
        pairs = [m, *c, *inertia]
        return LinkValues.from_tuple([lo for lo, _ in pairs]), LinkValues.from_tuple([hi for _, hi in pairs])

    def coefficient(self, value, field) -> IdentifiedCoefficient:
        value = self.mapping(value, field, {"coefficient", "value"})
        expr = value.get("coefficient")
        if not isinstance(expr, str) or not expr.strip():
            self.fail(f"{field}.coefficient", f"expected an expression string like \"c7y*m7\", got {_describe(expr)}")
        return IdentifiedCoefficient(expr, self.number(value.get("value"), f"{field}.value"))


def _describe(value) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    if value is None:
        return "nothing"
    if isinstance(value, (dict, list)):
        return f"a {'mapping' if isinstance(value, dict) else 'list'}"
    return repr(value)
