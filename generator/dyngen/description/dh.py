"""A DH table as joint models (joint_model.py): the two conventions differ only here.

standard (classical): T(i-1,i) = Rz(theta) Tz(d) Tx(a) Rx(alpha); joint i turns about z(i-1),
    so the joint frame sits at O(i-1) and the link frame is Tz(d) Tx(a) Rx(alpha) after it.
modified (Craig):     T(i-1,i) = Rx(alpha) Tx(a) Rz(theta) Tz(d); joint i turns about z(i),
    so the joint frame is link frame i.
A revolute joint adds q to theta, a prismatic one adds q to d: that coordinate is the motion,
its constant part the motion's offset; Rz and Tz commute, so the other one may sit on either
side of the motion.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .joint_model import JointModel, Rigid

if TYPE_CHECKING:
    from .robot import Joint

CONVENTIONS = ("standard", "modified")


def joint_model(convention: str, joint: Joint) -> JointModel:
    a, alpha, d, theta = joint.a, joint.alpha, joint.d, joint.theta
    if convention == "standard":
        if joint.revolute:
            return JointModel(joint.type, Rigid.identity(), theta, Rigid.trans(z=d) * Rigid.trans(x=a) * Rigid.rot_x(alpha))
        return JointModel(joint.type, Rigid.rot_z(theta), d, Rigid.trans(x=a) * Rigid.rot_x(alpha))
    if convention == "modified":
        if joint.revolute:
            return JointModel(joint.type, Rigid.rot_x(alpha) * Rigid.trans(x=a) * Rigid.trans(z=d), theta, Rigid.identity())
        return JointModel(joint.type, Rigid.rot_x(alpha) * Rigid.trans(x=a) * Rigid.rot_z(theta), d, Rigid.identity())
    raise ValueError(f"unknown DH convention {convention!r}")


def joint_models(convention: str, joints) -> tuple[JointModel, ...]:
    return tuple(joint_model(convention, joint) for joint in joints)
