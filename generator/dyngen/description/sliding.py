"""Link frames that keep the generated code short: each joint frame slid along its own axis.

A joint's frame may sit anywhere on its axis: moving link frame i by lambda along z_i is
T(i-1, i) Tz(lambda), and Tz commutes with the joint's motion (Rz or Tz), so only placement_i
(times Tz(lambda)), placement_(i+1) (Tz(-lambda) times it) and link i's centre of mass (minus
lambda z) change; the torques do not. A DH table makes the same choice (the frame on the common
normal); here the lambdas are picked to zero the most offset components of all placements
(the recursion multiplies by every non-zero one).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .joint_model import JointModel, Rigid
from .lumping import Body


def slide(models: list, bodies: list) -> tuple[list, list, list]:
    """models: JointModels with frame = I; bodies: (link name, Body in link frame i).
    Returns the slid models and bodies and each lambda.

    The offsets of placement i become p_i + lambda_i z_i - lambda_(i-1) e_z (z_i: joint i's axis
    in frame i-1). lambda_i is chosen by dynamic programming over the joints (the state is the
    previous lambda), so that an offset can travel along a run of parallel axes to where it
    costs least, as DH's d does (the UR5's shoulder and wrist offsets end in one length)."""
    n = len(models)
    axes = [m.placement.R[:, 2] for m in models]
    offsets = [m.placement.p for m in models]
    e_z = sp.ImmutableMatrix([0, 0, 1])

    def offset(i, before, lam):
        return offsets[i] + lam * axes[i] - before * e_z

    def zeros(vector):
        return sum(1 for x in vector if x == 0)

    best = {sp.Integer(0): (0, 0, ())}  # lambda_(i-1) -> (zeros so far, -moves, lambdas so far)
    for i in range(n):
        following = {sp.Integer(0)}
        if i + 1 < n:
            following.add(offsets[i + 1][2])
        step = {}
        for before, (score, moves, chosen) in sorted(best.items(), key=lambda kv: (abs(kv[0]), kv[0])):
            candidates = set(following) | {sp.Integer(0)}
            candidates |= {-(offsets[i][k] - before * e_z[k]) / axes[i][k] for k in range(3) if axes[i][k] != 0}
            for lam in sorted(candidates, key=lambda x: (abs(x), x)):  # a fixed order: same input, same frames
                entry = (score + zeros(offset(i, before, lam)), moves - (lam != 0), chosen + (lam,))
                if lam not in step or entry[:2] > step[lam][:2]:
                    step[lam] = entry
        best = step
    # most zeros, then fewest frames moved, then the smallest moves (deterministic: exact numbers)
    last = max(best.values(), key=lambda entry: (entry[0], entry[1], -sum(abs(x) for x in entry[2])))
    lambdas = list(last[2])
    slid, moved = [], []
    for i, model in enumerate(models):
        before = lambdas[i - 1] if i else sp.Integer(0)
        placement = Rigid.trans(z=-before) * model.placement * Rigid.trans(z=lambdas[i])
        slid.append(JointModel(model.type, placement, model.offset, model.frame))
        link, body = bodies[i]
        moved.append((link, Body(body.mass, body.com - np.array([0.0, 0.0, float(lambdas[i])]), body.inertia)))
    return slid, moved, lambdas
