"""Link frames that keep the generated code short: each joint frame slid along its own axis.

A joint's frame may sit anywhere on its axis: moving link frame i by lambda along z_i is
T(i-1, i) Tz(lambda), and Tz commutes with the joint's motion (Rz or Tz), so only placement_i
(times Tz(lambda)), placement_(i+1) (Tz(-lambda) times it) and link i's centre of mass (minus
lambda z) change; the torques do not. A DH table makes the same choice (the frame on the common
normal); here lambda is picked, joint by joint, to zero the most components of the two
placements' offsets (the recursion multiplies by every non-zero one), e.g. the UR5's 0.1197 m
shoulder offset along two parallel axes.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .joint_model import JointModel, Rigid
from .lumping import Body


def slide(models: list, bodies: list) -> tuple[list, list, list]:
    """models: JointModels with frame = I; bodies: (link name, Body in link frame i).
    Returns the slid models and bodies and each lambda."""
    models, bodies = list(models), list(bodies)
    lambdas = [sp.Integer(0)] * len(models)
    for i, model in enumerate(models):
        axis = model.placement.R[:, 2]  # z_i in frame i-1
        following = models[i + 1].placement.p if i + 1 < len(models) else None
        candidates = {sp.Integer(0)}
        candidates |= {-model.placement.p[k] / axis[k] for k in range(3) if axis[k] != 0}
        if following is not None:
            candidates.add(following[2])

        def zeros(lam):
            own = sum(1 for x in model.placement.p + lam * axis if x == 0)
            return own + (sum(1 for x in following - lam * sp.ImmutableMatrix([0, 0, 1]) if x == 0)
                          if following is not None else 0)

        lam = max(sorted(candidates, key=lambda x: (abs(x), x)), key=zeros)  # ties: the smallest move
        if lam == 0:
            continue
        lambdas[i] = lam
        models[i] = JointModel(model.type, model.placement * Rigid.trans(z=lam), model.offset, model.frame)
        if following is not None:
            nxt = models[i + 1]
            models[i + 1] = JointModel(nxt.type, Rigid.trans(z=-lam) * nxt.placement, nxt.offset, nxt.frame)
        link, body = bodies[i]
        bodies[i] = (link, Body(body.mass, body.com - np.array([0.0, 0.0, float(lam)]), body.inertia))
    return models, bodies, lambdas
