"""Random physically consistent link parameters, for tests."""
from __future__ import annotations

import numpy as np


def random_rotation(rng) -> np.ndarray:
    """Uniform random rotation (QR of a Gaussian matrix, signs fixed, det +1)."""
    Q, R = np.linalg.qr(rng.standard_normal((3, 3)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


def random_link(rng, mass=(0.5, 5.0), com_box=0.1, second_moment=(0.002, 0.05)) -> np.ndarray:
    """One link's dynamic parameters [m, cx, cy, cz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz].
    Principal moments are built from positive second moments (a, b, c) of a mass
    distribution as (b + c, a + c, a + b), so they are positive and satisfy the strict
    triangle inequality; the axes are rotated randomly: I = R diag(eigs) R^T."""
    m = rng.uniform(*mass)
    c = rng.uniform(-com_box, com_box, 3)
    a, b, cc = m * rng.uniform(*second_moment, 3)
    R = random_rotation(rng)
    I = R @ np.diag([b + cc, a + cc, a + b]) @ R.T
    return np.array([m, *c, I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]])


def random_parameters(n_links: int, seed=None, **kw) -> np.ndarray:
    """Dynamic parameters p (10N) for n_links links; seed: int or np.random.Generator."""
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    return np.concatenate([random_link(rng, **kw) for _ in range(n_links)])


def is_consistent(p, tol=0.0) -> bool:
    """m > 0, inertia about the CoM positive definite and satisfying the triangle inequality."""
    P = np.asarray(p, dtype=float).reshape(-1, 10)
    for m, _, _, _, xx, xy, xz, yy, yz, zz in P:
        I = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        e = np.linalg.eigvalsh(I)
        if m <= tol or e[0] <= tol or e[0] + e[1] < e[2] - tol:
            return False
    return True
