"""A URDF's serial chain as a Robot: joint models in Pinocchio's shape, nominal parameters from
the inertials (docs/urdf.md).

A URDF joint is a placement (origin xyz, rpy) followed by a turn about, or a slide along, its
unit axis u. With R_u the rotation taking z to u, that is  placement * R_u * motion_z(q) * R_u^T,
so the joint frame J_i is the placement turned by R_u. dyngen's link frame i is J_i itself
(z along the axis, frame_i = I, as in modified DH): the URDF's child link frame is J_i turned by
R_u^T (the same frame when the axis is z, as in most URDFs), folded into the next placement and
into the link's inertial (docs/urdf.md). Fixed joints are folded into
the next joint's placement and their links' inertials into the body (lumping.py); links beyond
the tip are locked at zero and lumped into the tip.
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import sympy as sp

from ..errors import InputError, shorten
from . import snapping
from .angles import cos_sin
from .joint_model import PRISMATIC, REVOLUTE, JointModel, Rigid, _floats
from .lumping import Body
from .robot import Joint, Limits, LinkValues, Robot
from .sliding import slide
from .snap_effect import snap_effects
from .urdf_xml import read_urdf

MOVING = {"revolute": REVOLUTE, "continuous": REVOLUTE, "prismatic": PRISMATIC}
MIN_MASS = 1e-9  # kg: a moving body lighter than this is an error (no arm has one)


def load_urdf(path, base_link=None, tip_link=None, snap=True, name=None, gravity=None, source=None) -> Robot:
    urdf = read_urdf(path)
    source = source or urdf.source

    def fail(element, message):
        raise InputError(source, element, message)

    children, parent_joint = {}, {}
    for joint in urdf.joints:
        if joint.child in parent_joint:
            fail(f'joint "{shorten(joint.name)}"', f'link "{shorten(joint.child)}" has a second parent: a closed '
                 "loop, which a serial chain cannot have")
        parent_joint[joint.child] = joint
        children.setdefault(joint.parent, []).append(joint)
    roots = [link for link in urdf.links if link not in parent_joint]
    if len(roots) != 1:
        fail("robot", f"expected one root link, found {len(roots)}: {', '.join(map(shorten, roots[:6]))}")
    base = base_link or roots[0]
    if base not in urdf.links:
        fail("base_link", f"no link named {shorten(base)!r}")
    tip = tip_link or _unique_leaf(urdf, base, children, fail)
    if tip not in urdf.links:
        fail("tip_link", f"no link named {shorten(tip)!r}")
    path_joints = []
    link = tip
    while link != base:
        if link not in parent_joint:
            fail("tip_link", f"{shorten(tip)!r} does not hang below base link {shorten(base)!r}")
        path_joints.append(parent_joint[link])
        link = parent_joint[link].parent
    path_joints.reverse()
    on_path = {j.name for j in path_joints}

    snaps, notes = [], []
    models, joints, bodies, link_frames = [], [], [], []
    fixed = Rigid.identity()  # from the current body's frame (or the base) to the joint reached
    body, body_link = None, None
    for joint in path_joints:
        where = f'joint "{shorten(joint.name)}"'
        if joint.mimic or joint.type in ("floating", "planar"):
            fail(where, f"a {'mimic' if joint.mimic else joint.type} joint cannot be part of dyngen's serial "
                 "chain (choose tip_link before it)")
        origin = _origin(joint, snaps, snap)
        if body is not None:
            body = body + _subtree(urdf, joint.parent, children, on_path, fixed, source, notes, tip, snap, snaps)
        if joint.type == "fixed":
            fixed = fixed * origin
            continue
        if body is not None:
            bodies.append((body_link, body))
        u = snapping.axis(joint.axis, joint.name, snaps, snap)
        align = _align(u)
        # Link frame i is the joint frame (frame_i = I, as in modified DH: the shortest code); the
        # URDF child link sits in it turned by R_u^T, which the next placement and the inertials absorb.
        models.append(JointModel(MOVING[joint.type], fixed * origin * align, sp.Integer(0), Rigid.identity()))
        joints.append(Joint(MOVING[joint.type], 0, 0, 0, 0, _limits(joint)))
        fixed = Rigid(sp.ImmutableMatrix(align.R.T), align.p)
        link_frames.append(fixed)
        body, body_link = Body.empty(), joint.child
    if not models:
        fail("tip_link", f"no revolute, continuous or prismatic joint between {shorten(base)!r} and {shorten(tip)!r}")
    body = body + _subtree(urdf, tip, children, on_path, fixed, source, notes, tip, snap, snaps)
    bodies.append((body_link, body))
    models, bodies, lambdas = slide(models, bodies)
    link_frames = [Rigid.trans(z=-lam) * frame for lam, frame in zip(lambdas, link_frames)]
    nominal = []
    for link, b in bodies:
        if b.mass < MIN_MASS:
            missing = urdf.links[link].inertial is None
            fail(f'link "{shorten(link)}".inertial', "missing" if missing else
                 f"the body moved by this link's joint has no mass ({b.mass:g} kg)")
        I = b.inertia
        nominal.append(LinkValues(float(b.mass), tuple(float(x) for x in b.com),
                                  (I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2])))
    robot_name = name or _c_name(urdf.name)
    robot = Robot(name=robot_name, source=source, convention="urdf", joints=tuple(joints),
                 gravity=tuple(gravity or (sp.Integer(0), sp.Integer(0), sp.Rational("-9.81"))),
                 nominal=tuple(nominal), models=tuple(models), snaps=tuple(snaps), notes=tuple(notes),
                 links=tuple(link for link, _ in bodies), link_frames=tuple(link_frames),
                 joint_names=tuple(j.name for j in path_joints if j.type != "fixed"),
                 urdf_file=str(Path(path).resolve()),
                 urdf_options={"base_link": base_link, "tip_link": tip_link, "snap": snap})
    if robot.snaps and snap is True:  # each snap's effect, from the file read with that one kept
        effects = snap_effects(robot, lambda keep: load_urdf(path, base_link, tip_link, keep, name, gravity, source))
        robot = replace(robot, snap_effects=effects)
    return robot


def _unique_leaf(urdf, base, children, fail):
    """The link after the last moving joint on the way to every leaf, when all leaves agree (a
    tool frame or a sensor fixed to the flange is lumped); leaves with no moving joint above them
    (a fixed base plate) do not count."""
    ends, stack = {}, [(base, None)]
    while stack:
        link, last_moving = stack.pop()
        below = children.get(link, [])
        if not below and last_moving is not None:
            ends.setdefault(last_moving, []).append(link)
        stack.extend((j.child, j.child if j.type in MOVING else last_moving) for j in below)
    if len(ends) != 1:
        leaves = sorted(shorten(leaf) for group in ends.values() for leaf in group)
        fail("tip_link", f"the tree has {len(leaves)} leaves ({', '.join(leaves[:8])}); say which is the tip: "
             "--tip-link NAME, or tip_link: NAME in a YAML that points to the URDF")
    return next(iter(ends))


def _subtree(urdf, link, children, on_path, to_body: Rigid, source, notes, tip, snap, snaps) -> Body:
    """Link `link`'s own inertial and every off-chain link below it (locked at q = 0), in the
    body's frame (to_body: link's frame in it). A moving joint off the chain is allowed only
    beyond the tip: mid-chain it would be a branch. Their placements' snaps are reported too
    (a gripper's rpy written 1.5708 moves the lumped centre of mass)."""
    total = _inertial(urdf.links[link])
    R, p = _floats(to_body.R), _floats(to_body.p)[:, 0]
    total = total.moved(R, p)
    for joint in children.get(link, []):
        if joint.name in on_path:
            continue
        if joint.type != "fixed":
            if link != tip and not _below(urdf, tip, link):
                raise InputError(source, f'joint "{shorten(joint.name)}"', "moves a branch off the chain; a "
                                 "branching tree needs tip_link set to one branch's end")
            notes.append(f'joint "{joint.name}" beyond the tip is locked at 0 and its links lumped into the tip')
        total = total + _subtree(urdf, joint.child, children, on_path, to_body * _origin(joint, snaps, snap),
                                 source, notes, tip, snap, snaps)
    return total


def _below(urdf, tip, link) -> bool:
    """Whether link hangs below the tip (beyond the chain's end)."""
    parents = {j.child: j.parent for j in urdf.joints}
    while link in parents:
        link = parents[link]
        if link == tip:
            return True
    return False


def _inertial(link) -> Body:
    if link.inertial is None:
        return Body.empty()
    inertial = link.inertial
    R = _rpy_numeric([float(x) for x in inertial.rpy])
    xx, xy, xz, yy, yz, zz = inertial.inertia
    I = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    return Body(inertial.mass, np.array([float(x) for x in inertial.xyz]), R @ I @ R.T)


def _origin(joint, snaps, snap) -> Rigid:
    xyz = [snapping.length(t) for t in joint.xyz]
    roll, pitch, yaw = (snapping.angle(t, joint.name, f"origin.rpy[{k}]", snaps, snap) for k, t in enumerate(joint.rpy))
    return Rigid(_rpy(roll, pitch, yaw), sp.ImmutableMatrix(xyz))


def _rpy(roll, pitch, yaw) -> sp.ImmutableMatrix:
    """URDF's fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll), exact."""
    (cr, sr), (cp, sp_), (cy, sy) = cos_sin(roll), cos_sin(pitch), cos_sin(yaw)
    Rz = sp.Matrix([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    Ry = sp.Matrix([[cp, 0, sp_], [0, 1, 0], [-sp_, 0, cp]])
    Rx = sp.Matrix([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return sp.ImmutableMatrix(Rz * Ry * Rx)


def _rpy_numeric(rpy) -> np.ndarray:
    return _floats(_rpy(*(sp.Float(v, 30) for v in rpy))) if any(rpy) else np.eye(3)


def _align(u) -> Rigid:
    """A rotation taking z to the unit axis u: exact integers for +-x, +-y, +-z; otherwise u is made
    an exact rational unit vector (stereographic projection) and R = I + K + K^2 / (1 + u_z)."""
    if all(isinstance(x, sp.Integer) for x in u):
        u = [int(x) for x in u]
        if u == [0, 0, 1]:
            return Rigid.identity()
        if u == [0, 0, -1]:
            return Rigid(sp.ImmutableMatrix(sp.diag(1, -1, -1)), sp.ImmutableMatrix(sp.zeros(3, 1)))
    else:
        x, y, z = (float(v) for v in u)
        if z < -0.999999:
            return Rigid(sp.ImmutableMatrix(sp.diag(1, -1, -1)), sp.ImmutableMatrix(sp.zeros(3, 1)))
        a, b = (sp.Rational(v / (1 + z)).limit_denominator(10**8) for v in (x, y))
        n = 1 + a * a + b * b
        u = [2 * a / n, 2 * b / n, (1 - a * a - b * b) / n]
    K = sp.Matrix([[0, 0, u[0]], [0, 0, u[1]], [-u[0], -u[1], 0]])  # skew(z x u)
    R = sp.eye(3) + K + K * K / (1 + u[2])
    return Rigid(sp.ImmutableMatrix(R), sp.ImmutableMatrix(sp.zeros(3, 1)))


def _limits(joint) -> Limits:
    return Limits(lower=joint.lower, upper=joint.upper, velocity=joint.velocity or None, effort=joint.effort or None)


def _c_name(text: str) -> str:
    name = re.sub(r"[^a-z0-9_]", "_", text.lower()).strip("_") or "arm"
    if not name[0].isalpha():
        name = "arm_" + name
    return name[:40]
