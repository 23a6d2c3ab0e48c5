"""The identification's normal equations (identification/normal.py) against numpy's own products
of the rows: a tilt's rotation done as algebra on the summed blocks (Normal.rotated) equals the
normal equations of rows whose tilt columns were rotated before summing."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from dyngen.identification.normal import Normal

DOF, R = 3, 4
LABELS = [("offset", 0), ("offset", 2), ("tilt", "x"), ("tilt", "y")]


def pieces(rng, along_scale=1.0, rotate=None):
    """Two pieces of random rows over two parts; rotate: {label index: beta} applied to the rows."""
    out = []
    for t in (50, 70):
        columns = {("offset", 0): rng.normal(size=t), ("offset", 2): rng.normal(size=t),
                   ("tilt", "x"): rng.normal(size=(t, DOF)), ("tilt", "y"): rng.normal(size=(t, DOF))}
        along = along_scale * rng.normal(size=(t, DOF))
        if rotate:
            for k, beta in rotate.items():
                columns[LABELS[k]] = columns[LABELS[k]] - beta * along
        part = (np.arange(t) >= t // 3).astype(int)  # two contiguous parts in each piece
        out.append(SimpleNamespace(Yj=[rng.normal(size=(t, R)) for _ in range(DOF)], columns=columns,
                                   tau=rng.normal(size=(t, DOF)), part=part, along=along))
    return out


def test_the_blocks_are_the_rows_products():
    rows = pieces(np.random.default_rng(1))
    normal = Normal.build(rows, LABELS, R, parts=2, dof=DOF)
    j, p = 2, 1  # joint 2 sees the coefficients, its own offset and both tilt columns
    A = np.vstack([np.hstack([pc.Yj[j], pc.columns[("offset", 2)][:, None], pc.columns[("tilt", "x")][:, j:j + 1],
                              pc.columns[("tilt", "y")][:, j:j + 1]])[pc.part == p] for pc in rows])
    b = np.concatenate([pc.tau[pc.part == p, j] for pc in rows])
    idx = [0, 1, 2, 3, R + 1, R + 2, R + 3]
    assert np.allclose(normal.G[p, j][np.ix_(idx, idx)], A.T @ A, rtol=1e-12, atol=1e-12)
    assert np.allclose(normal.g[p, j][idx], A.T @ b, rtol=1e-12, atol=1e-12)
    assert np.isclose(normal.bb[p, j], b @ b) and normal.n[p, j] == b.size
    assert not normal.G[p, j][R, :].any()  # joint 0's offset never meets joint 2's rows


def test_rotating_the_summed_blocks_equals_rotating_the_rows():
    betas = {2: 0.3, 3: -1.7}
    hidden = Normal.build(pieces(np.random.default_rng(7)), LABELS, R, parts=2, dof=DOF, hidden=1)
    rotated = hidden.rotated(list(betas), list(betas.values()))
    direct = Normal.build(pieces(np.random.default_rng(7), rotate=betas), LABELS, R, parts=2, dof=DOF, hidden=1)
    c = R + len(LABELS)  # the hidden column itself is no unknown: compare the unknowns' blocks
    assert np.allclose(rotated.G[:, :, :c, :c], direct.G[:, :, :c, :c], rtol=1e-11, atol=1e-11)
    assert np.allclose(rotated.g[:, :, :c], direct.g[:, :, :c], rtol=1e-11, atol=1e-11)
    unrotated = hidden.G[:, :, :c, :c]
    assert not np.allclose(unrotated, direct.G[:, :, :c, :c])  # the rotation does change them
