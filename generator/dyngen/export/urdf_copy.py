"""Parameters written back into a copy of the user's URDF: link names, joints, limits, meshes and
comments kept; only the inertial of each moving chain link changes.

dyngen's body i is the chain link plus everything lumped into it (links behind fixed joints,
links beyond the tip). Those other links keep their inertials as the user wrote them, and the
chain link gets the rest: s_link = s_body(new) - (s_body(file) - s_link(file)), exact because the
standard parameters s (mass, first moment, inertia about the frame origin) add. It is written in
the URDF link's own frame (the robot's link_frames), with its centre-of-mass inertia.

That rest can be a valid sum but not a physical body of its own (a hand lumped beyond the tip,
parameters moved a few per cent: the chain link's inertia breaks the triangle inequality, and
MuJoCo refuses the file). Then the lumped links' inertials are scaled by the largest factor k
in [0, 1] that leaves the chain link physical (their centres of mass kept; the body's sum, so
the dynamics, unchanged), and a comment in the link says by how much.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import defusedxml.ElementTree as SafeET
import numpy as np

from ..description.joint_model import _floats
from ..description.urdf import _inertial, load_urdf
from ..description.urdf_xml import MAX_URDF_BYTES, read_urdf
from ..errors import InputError
from ..parameters import consistency_problem, inertia_array
from ..untrusted import read_text


def _s(m, c, I):
    """Standard parameters about the frame origin: (m, m c, J) with J = I + m (c.c E - c c^T)."""
    c = np.asarray(c, dtype=float)
    return m, m * c, I + m * (c @ c * np.eye(3) - np.outer(c, c))


def _link_values(values):
    return _s(values.m, values.c, inertia_array(values.I))


def urdf_copy(robot, p) -> str:
    if robot.urdf_file is None:
        raise ValueError("the robot was not read from a URDF")
    original = load_urdf(robot.urdf_file, **robot.urdf_options)
    file = read_urdf(robot.urdf_file)
    text = read_text(robot.urdf_file, MAX_URDF_BYTES)
    SafeET.fromstring(text, forbid_dtd=True, forbid_entities=True, forbid_external=True)  # read_urdf's check again
    # No DTD (checked above), so the standard parser cannot expand anything; it keeps the comments.
    root = ET.fromstring(text, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))
    p = np.asarray(p, dtype=float).reshape(robot.dof, 10)
    for i, link in enumerate(robot.links):
        frame = original.link_frames[i]
        R, t = _floats(frame.R), _floats(frame.p)[:, 0]
        own = file.links[link].inertial
        m_own, h_own, J_own = 0.0, np.zeros(3), np.zeros((3, 3))
        if own is not None:
            body = _inertial(file.links[link]).moved(R, t)
            m_own, h_own, J_own = _s(body.mass, body.com, body.inertia)
        m_file, h_file, J_file = _link_values(original.nominal[i])
        m_new, h_new, J_new = _s(p[i, 0], p[i, 1:4], inertia_array(p[i, 4:]))
        k = _largest_share(m_new, h_new, J_new, m_file - m_own, h_file - h_own, J_file - J_own)
        m = m_new - k * (m_file - m_own)
        h = h_new - k * (h_file - h_own)
        J = J_new - k * (J_file - J_own)
        if k < 1:
            _scale_lumped(root, file, link, set(robot.links), link == robot.links[-1], k)
        if m <= 0:
            raise InputError(robot.source, f'link "{link}"', "the new mass is smaller than that of the links "
                             "lumped into it; the copy cannot keep their inertials")
        c = h / m
        I_com = J - m * (c @ c * np.eye(3) - np.outer(c, c))
        c_link, I_link = R.T @ (c - t), R.T @ I_com @ R  # into the URDF link's frame
        _set_inertial(root, link, m, c_link, I_link)
    prefix = text[:text.index("<robot")] if "<robot" in text else ""
    prefix = "\n".join(line for line in prefix.splitlines() if not line.startswith("<?xml"))
    return '<?xml version="1.0" encoding="utf-8"?>\n' + prefix + "\n" + ET.tostring(root, encoding="unicode") + "\n"


# MuJoCo checks the triangle inequality in its own rounding (of the file's decimal text and its
# diagonalisation): a chain link written exactly on the boundary can be refused, so keep room.
MUJOCO_ROOM = 1e-3


def _physical(m, h, J) -> bool:
    """Standard parameters about the frame origin (m, m c, J) that a simulator loads: their
    dynamic form is parameters.consistency_problem-free with room MUJOCO_ROOM."""
    if m <= 0:
        return False
    c = h / m
    I = J - m * (c @ c * np.eye(3) - np.outer(c, c))
    link10 = [m, *c, I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]]
    return consistency_problem(link10, MUJOCO_ROOM) is None


def _largest_share(m_new, h_new, J_new, m_others, h_others, J_others) -> float:
    """The largest k in [0, 1] (1, or found to 1e-6 by bisection) with s_new - k s_others physical."""
    def ok(k):
        return _physical(m_new - k * m_others, h_new - k * h_others, J_new - k * J_others)

    if m_others == 0 or ok(1.0) or not ok(0.0):
        return 1.0
    lo, hi = 0.0, 1.0
    while hi - lo > 1e-6:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


def _scale_lumped(root, file, link, chain, is_tip, k):
    """Scale mass and inertia of every link lumped into chain link `link` by k (in the XML)."""
    children = {}
    for joint in file.joints:
        children.setdefault(joint.parent, []).append(joint)
    lumped, todo = [], [link]
    while todo:
        for joint in children.get(todo.pop(), []):
            if joint.child not in chain and (joint.type == "fixed" or is_tip):
                lumped.append(joint.child)
                todo.append(joint.child)
    for element in root.findall("link"):
        if element.get("name") in lumped and element.find("inertial") is not None:
            inertial = element.find("inertial")
            mass = inertial.find("mass")
            mass.set("value", repr(float(mass.get("value")) * k))
            inertia = inertial.find("inertia")
            for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                if inertia.get(key) is not None:
                    inertia.set(key, repr(float(inertia.get(key)) * k))
    element = next(e for e in root.findall("link") if e.get("name") == link)
    element.insert(0, ET.Comment(f" dyngen: the inertials of {', '.join(lumped)} scaled by {k:.6g} so that "
                                 f"{link} stays a physical body (the sum is the extracted one) "))


def _set_inertial(root, link, m, c, I):
    element = next(e for e in root.findall("link") if e.get("name") == link)
    old = element.find("inertial")
    if old is not None:
        element.remove(old)
    inertial = ET.SubElement(element, "inertial")
    ET.SubElement(inertial, "origin", xyz=" ".join(repr(float(x)) for x in c), rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=repr(float(m)))
    ET.SubElement(inertial, "inertia", **{k: repr(float(I[a, b])) for k, (a, b) in
                                            zip(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"),
                                                ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)))})
