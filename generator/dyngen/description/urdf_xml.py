"""A URDF file as plain values: links (inertials, mesh file names) and joints, nothing computed.

Parsed with defusedxml (docs/urdf.md says why): a DTD is refused outright, so neither an
entity expansion ("billion laughs") nor an external entity can be written into the file. The
bytes are read through untrusted.read_text (size bound, UTF-8). Every problem is an
InputError naming the file and the element, e.g. `arm.urdf: joint "j2".axis: ...`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Optional

import defusedxml
import defusedxml.ElementTree as SafeET

from ..errors import InputError, shorten
from ..untrusted import read_text

MAX_URDF_BYTES = 8 << 20
MAX_LINKS = 200
MAX_VALUE = 1e5  # lengths [m], masses [kg], inertias [kg m^2]: far beyond any serial arm
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
XACRO_NAMESPACE = "{http://www.ros.org/wiki/xacro}"
XACRO_REFUSED = ("a xacro file is a program (its ${...} are Python expressions; $(find ...), $(env ...) and "
                 "xacro:include read other files and the environment), which dyngen does not run: expand it where "
                 "you trust it (xacro arm.urdf.xacro > arm.urdf) and give dyngen the URDF")


@dataclass(frozen=True)
class Inertial:
    xyz: tuple  # centre of mass in the link frame, as decimal strings
    rpy: tuple  # inertial frame in the link frame
    mass: float
    inertia: tuple  # ixx, ixy, ixz, iyy, iyz, izz about the centre of mass, inertial-frame axes


@dataclass(frozen=True)
class UrdfLink:
    name: str
    inertial: Optional[Inertial]


@dataclass(frozen=True)
class UrdfJoint:
    name: str
    type: str
    parent: str
    child: str
    xyz: tuple  # decimal strings, kept as written (lengths become their decimal value)
    rpy: tuple
    axis: tuple
    lower: Optional[float]
    upper: Optional[float]
    velocity: Optional[float]
    effort: Optional[float]
    mimic: bool


@dataclass(frozen=True)
class UrdfFile:
    name: str
    source: str
    links: dict  # name -> UrdfLink, in file order
    joints: tuple  # UrdfJoint, in file order


class _Reader:
    def __init__(self, source: str):
        self.source = source

    def fail(self, element: str, message: str):
        raise InputError(self.source, element, message)

    def numbers(self, text, where, count):
        parts = (text or "").split()
        if len(parts) != count:
            self.fail(where, f"expected {count} numbers, got {shorten(text or 'nothing')!r}")
        for part in parts:
            try:
                value = float(part)
            except ValueError:
                self.fail(where, f"expected a number, got {shorten(part)!r}")
            if not math.isfinite(value) or abs(value) > MAX_VALUE:
                self.fail(where, f"expected a finite number of at most {MAX_VALUE:g} in size, got {shorten(part)!r}")
        return tuple(parts)

    def number(self, element, key, where, default=None):
        text = element.get(key) if element is not None else None
        if text is None:
            if default is None:
                self.fail(where, f"missing {key}")
            return default
        return float(self.numbers(text, f"{where}.{key}", 1)[0])

    def origin(self, element, where):
        origin = element.find("origin")
        if origin is None:
            return ("0", "0", "0"), ("0", "0", "0")
        return (self.numbers(origin.get("xyz", "0 0 0"), f"{where}.origin.xyz", 3),
                self.numbers(origin.get("rpy", "0 0 0"), f"{where}.origin.rpy", 3))


def read_urdf(path) -> UrdfFile:
    path = Path(path)
    reader = _Reader(path.name)
    if path.suffix.lower() == ".xacro":
        reader.fail("", XACRO_REFUSED)
    text = read_text(path, MAX_URDF_BYTES)
    try:
        root = SafeET.fromstring(text, forbid_dtd=True, forbid_entities=True, forbid_external=True)
    except defusedxml.DefusedXmlException as err:
        reader.fail("", f"refused: the XML declares a DTD or entities ({type(err).__name__}); a URDF needs neither")
    except SafeET.ParseError as err:
        reader.fail(f"line {err.position[0]}", f"not well-formed XML ({shorten(str(err))})")
    if root.tag != "robot":
        reader.fail(shorten(root.tag), "expected a <robot> element at the top")
    for element in root.iter():
        if str(element.tag).startswith(XACRO_NAMESPACE) or any("${" in v or "$(" in v for v in element.attrib.values()):
            reader.fail(shorten(str(element.tag).replace(XACRO_NAMESPACE, "xacro:")), XACRO_REFUSED)
    links = {}
    for element in root.findall("link"):
        name = element.get("name")
        where = f'link "{shorten(name)}"'
        if not name or name in links:
            reader.fail(where, "a link needs a name, unique in the file")
        _check_meshes(reader, element, where, path)
        links[name] = UrdfLink(name, _inertial(reader, element.find("inertial"), where))
        if len(links) > MAX_LINKS:
            reader.fail("robot", f"more than {MAX_LINKS} links")
    joints = tuple(_joint(reader, element, links) for element in root.findall("joint"))
    return UrdfFile(root.get("name") or path.stem, path.name, links, joints)


def _check_meshes(reader, element, where, path):
    """A mesh is named relative to the URDF's folder (or as package://); none may leave the folder."""
    for mesh in element.iter("mesh"):
        name = mesh.get("filename") or ""
        relative = name.split("://", 1)[1].split("/", 1)[-1] if name.startswith("package://") else name
        relative = relative[len("file://"):] if relative.startswith("file://") else relative
        parts = PurePosixPath(relative).parts
        if not relative or PurePosixPath(relative).is_absolute() or ".." in parts or "\\" in relative:
            reader.fail(f"{where}.mesh", f"the mesh {shorten(name)!r} lies outside the URDF's folder")


def _inertial(reader, element, where) -> Optional[Inertial]:
    if element is None:
        return None
    where = f"{where}.inertial"
    xyz, rpy = reader.origin(element, where)
    mass = reader.number(element.find("mass"), "value", f"{where}.mass")
    if mass < 0:
        reader.fail(f"{where}.mass", f"a mass cannot be negative, got {mass:g}")
    inertia = element.find("inertia")
    if inertia is None:
        reader.fail(f"{where}.inertia", "missing")
    values = tuple(reader.number(inertia, k, f"{where}.inertia") for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
    return Inertial(xyz, rpy, mass, values)


def _joint(reader, element, links) -> UrdfJoint:
    name = element.get("name") or ""
    where = f'joint "{shorten(name)}"'
    kind = element.get("type")
    if kind not in JOINT_TYPES:
        reader.fail(f"{where}.type", f"unknown joint type {shorten(kind or 'nothing')!r}")
    ends = {}
    for end in ("parent", "child"):
        node = element.find(end)
        link = node.get("link") if node is not None else None
        if link not in links:
            reader.fail(f"{where}.{end}", f"names no link of the file ({shorten(link or 'nothing')!r})")
        ends[end] = link
    xyz, rpy = reader.origin(element, where)
    axis_element = element.find("axis")
    axis = reader.numbers(axis_element.get("xyz", "1 0 0"), f"{where}.axis.xyz", 3) if axis_element is not None \
        else ("1", "0", "0")  # the URDF default
    if kind in ("revolute", "prismatic", "continuous") and math.hypot(*map(float, axis)) < 1e-6:
        reader.fail(f"{where}.axis", "the axis has zero length")
    limit = element.find("limit")
    get = (lambda key: reader.number(limit, key, f"{where}.limit", default=math.nan)) if limit is not None \
        else (lambda key: math.nan)
    values = {k: get(k) for k in ("lower", "upper", "velocity", "effort")}
    values = {k: (None if math.isnan(v) else v) for k, v in values.items()}
    if kind == "continuous":
        values["lower"] = values["upper"] = None
    return UrdfJoint(name, kind, ends["parent"], ends["child"], xyz, rpy, axis, mimic=element.find("mimic") is not None,
                     **values)
