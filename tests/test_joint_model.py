"""The joint model (description/joint_model.py) filled from DH rows: its exact transform and
its numpy forward kinematics equal the DH formulas of the Lagrangian oracle, for both
conventions and both joint types, at arbitrary angles and offsets."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from oracles import lagrangian as lag

from dyngen.description import Joint
from dyngen.description.dh import joint_models
from dyngen.description.joint_model import forward_kinematics

ROWS = [  # type, a, alpha, d, theta (exact, as the loader gives them)
    ("revolute", sp.Rational(3, 10), -sp.pi / 2, sp.Rational(2, 5), sp.pi / 7),
    ("prismatic", sp.Rational(-1, 10), sp.Rational(7, 10), sp.Rational(1, 4), -sp.pi / 3),
    ("revolute", sp.Integer(0), sp.pi / 2, sp.Rational(-3, 10), sp.Integer(0)),
    ("prismatic", sp.Rational(1, 5), sp.Integer(0), sp.Integer(0), sp.Rational(1, 3)),
    ("revolute", sp.Rational(1, 20), sp.Rational(1, 3), sp.Integer(0), sp.Rational(-2, 5)),
]


def dh(convention, row, q):
    kind, a, alpha, d, theta = row
    revolute = kind == "revolute"
    return lag.dh_transform(convention, float(a), float(alpha), float(d) + (0.0 if revolute else q),
                            float(theta) + (q if revolute else 0.0))


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_exact_transform_is_the_dh_transform(convention):
    models = joint_models(convention, [Joint(*row) for row in ROWS])
    for model, row, q in zip(models, ROWS, (0.3, -0.2, 1.1, 0.05, -2.0)):
        exact = np.array(model.transform(sp.Float(q, 30)).evalf(30), dtype=float)
        assert np.allclose(exact, dh(convention, row, q), rtol=0, atol=1e-14)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_numpy_forward_kinematics_is_the_dh_product(convention):
    models = joint_models(convention, [Joint(*row) for row in ROWS])
    q = np.random.default_rng(3).uniform(-2, 2, size=(4, len(ROWS)))
    poses = forward_kinematics(models, q)
    for t in range(q.shape[0]):
        T = np.eye(4)
        for i, row in enumerate(ROWS):
            before = T
            T = T @ dh(convention, row, q[t, i])
            pose = poses[i]
            assert np.allclose(pose.R[t], T[:3, :3], atol=1e-13) and np.allclose(pose.origin[t], T[:3, 3], atol=1e-13)
            # the joint axis: z(i-1) in standard DH, z(i) in modified DH
            axis_frame = before if convention == "standard" else T
            assert np.allclose(pose.axis[t], axis_frame[:3, 2], atol=1e-13)
            if row[0] == "revolute":  # the point lies on the axis through that frame's origin
                offset = pose.point[t] - axis_frame[:3, 3]
                assert np.allclose(np.cross(offset, pose.axis[t]), 0, atol=1e-13)
