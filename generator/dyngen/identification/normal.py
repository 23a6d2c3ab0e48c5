"""Normal equations per part (fold) and joint, formed once: for part p and joint j, with A the
columns in joint j's rows there (coefficients, then labels) and b the torques,

    G[p, j] = A^T A,   g[p, j] = A^T b,   bb[p, j] = b^T b,   n[p, j] = rows

Any weighted fit on any union of parts is a sum of these, its residual bb - 2 x^T g + x^T G x."""

from __future__ import annotations

import numpy as np

from .least_squares import WEAK


def segments(part: np.ndarray) -> list:
    """(part, slice) of every run of equal part values (parts are contiguous stretches)."""
    if part.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(part)) + 1
    starts, stops = np.r_[0, cuts], np.r_[cuts, part.size]
    return [(int(part[a]), slice(int(a), int(b))) for a, b in zip(starts, stops)]


def touched(piece) -> np.ndarray:
    """The parts with samples in the piece: a block's sums elsewhere are zeros, neither sent back from
    its worker nor added (adding an exact zero changes no sum: the same sums, bitwise)."""
    return np.unique(piece.part)


def local_columns(labels, r: int, j: int, hidden: int) -> tuple[list[int], np.ndarray]:
    """(labels non-zero in joint j's rows, joint j's columns: the coefficients, those labels, the hidden)."""
    ks = [k for k, (kind, jj) in enumerate(labels) if kind == "tilt" or jj == j]
    return ks, np.r_[np.arange(r), r + np.asarray(ks, dtype=int), r + len(labels) + np.arange(hidden)]


def label_design(piece, labels, j: int, ks, hidden: int) -> np.ndarray:
    """(T, len(ks) + hidden): joint j's rows of the labels ks, then the hidden column."""
    columns = [piece.columns[labels[k]] for k in ks]  # (T,) for a joint's label, (T, N) for the arm's
    return np.column_stack([v[:, j] if v.ndim == 2 else v for v in columns]
                           + ([piece.along[:, j]] if hidden else []) + [np.zeros((piece.tau.shape[0], 0))])


def gram(Y: np.ndarray, L: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(A^T A, A^T b) of A = [Y L] without forming A (Y a strided view of the block's regressor)."""
    r, c = Y.shape[1], Y.shape[1] + L.shape[1]
    G = np.empty((c, c))
    G[:r, :r] = Y.T @ Y
    # L^T Y and b Y, not Y^T L and Y^T b: the same sums, bitwise, in 2/3 of the time (BLAS on the
    # strided view: the narrow operand first)
    G[r:, :r] = L.T @ Y
    G[:r, r:] = G[r:, :r].T
    G[r:, r:] = L.T @ L
    return G, np.r_[b @ Y, L.T @ b]


class Normal:
    def __init__(self, r: int, labels: list, parts: int, dof: int, hidden: int = 0):
        """hidden: trailing columns that are no label (the tilt's gravity along its axis, for rotated())."""
        self.r, self.labels, self.dof, self.hidden = r, list(labels), dof, hidden
        c = r + len(labels) + hidden
        self.G = np.zeros((parts, dof, c, c))
        self.g = np.zeros((parts, dof, c))
        self.bb = np.zeros((parts, dof))
        self.n = np.zeros((parts, dof))

    @classmethod
    def build(cls, pieces, labels, r: int, parts: int, dof: int, swaps=None, hidden: int = 0) -> "Normal":
        """swaps: summed in the same pass. Blocks summed on their own (Blocks.each) and added in block order."""
        out = cls(r, labels, parts, dof, hidden)

        def of_block(piece):
            own = cls(r, labels, parts, dof, hidden)
            own.add(piece)
            at = touched(piece)
            return (at, own.G[at], own.g[at], own.bb[at], own.n[at]), None if swaps is None else swaps.of_block(piece)

        for (at, *sums), swapped in (pieces.each(of_block) if hasattr(pieces, "each") else map(of_block, pieces)):
            for total, part in zip((out.G, out.g, out.bb, out.n), sums):
                total[at] += part
            if swapped is not None:
                swaps.added(*swapped)
        return out

    def add(self, piece) -> None:
        r, labels, hidden = self.r, self.labels, self.hidden
        for j in range(self.dof):
            ks, idx = local_columns(labels, r, j, hidden)
            L = label_design(piece, labels, j, ks, hidden)
            b = piece.tau[:, j]
            for p, sl in segments(piece.part):
                bm = b[sl]
                G, g = gram(piece.Yj[j][sl], L[sl], bm)
                self.G[p, j][np.ix_(idx, idx)] += G
                self.g[p, j][idx] += g
                self.bb[p, j] += bm @ bm
                self.n[p, j] += bm.size

    def swapped(self, blocks, ks, makes) -> list["Normal"]:
        """Per variant, self with the Coulomb columns ks those of makes[v] (Swaps), in one pass over the blocks."""
        swaps = Swaps(self.labels, self.r, self.G.shape[0], self.dof, ks, makes, self.hidden)
        for swapped in blocks.each(swaps.of_block):
            swaps.added(*swapped)
        return swaps.normals(self)

    def _with(self, G, g) -> "Normal":
        """The same rows' sums (labels, bb, n) with other G and g."""
        out = Normal.__new__(Normal)
        out.r, out.labels, out.dof, out.hidden, out.bb, out.n = self.r, self.labels, self.dof, self.hidden, self.bb, self.n
        out.G, out.g = G, g
        return out

    @classmethod
    def per_joint(cls, normals: list) -> "Normal":
        """Joint j's blocks from normals[j] (each differs from the others in joint columns only)."""
        return normals[0]._with(np.stack([m.G[:, j] for j, m in enumerate(normals)], axis=1),
                                np.stack([m.g[:, j] for j, m in enumerate(normals)], axis=1))

    def rotated(self, ks, betas) -> "Normal":
        """A copy with label ks[d]'s column c_d - betas[d] * w (w the first hidden column): M^T G M, M^T g."""
        M = np.eye(self.G.shape[-1])
        for k, beta in zip(ks, betas):
            M[self.r + len(self.labels), self.r + k] = -beta
        # two matrix products per block, not a four-index einsum (which loops over c^4 per block: 0.9 s)
        return self._with(M.T @ self.G @ M, self.g @ M)

    def total(self, parts, weights=None, keep=None) -> tuple[np.ndarray, np.ndarray]:
        """(A^T W A, A^T W b) over the parts, joint j weighted by weights[j]^2, on the columns `keep`."""
        w2 = np.ones(self.dof) if weights is None else np.asarray(weights, dtype=float) ** 2
        c = self.r + len(self.labels)  # the hidden columns are no unknowns
        G = np.einsum("pjab,j->ab", self.G[parts][:, :, :c, :c], w2)
        g = np.einsum("pja,j->a", self.g[parts][:, :, :c], w2)
        if keep is not None:
            G, g = G[np.ix_(keep, keep)], g[keep]
        return G, g

    def sse(self, x, parts, keep=None) -> np.ndarray:
        """(len(parts), N): sum of squared residuals of x (over the columns keep) per part and joint."""
        if keep is not None:
            full = np.zeros(self.r + len(self.labels))
            full[keep] = x
            x = full
        c = self.r + len(self.labels)
        G, g, bb = self.G[parts][:, :, :c, :c], self.g[parts][:, :, :c], self.bb[parts]
        return np.maximum(bb - 2 * np.einsum("pja,a->pj", g, x) + np.einsum("pjab,a,b->pj", G, x, x), 0.0)


class Swaps:
    """The Coulomb searches' variants: per joint one label (ks), variant v's columns makes[v](piece)."""

    def __init__(self, labels, r: int, parts: int, dof: int, ks, makes, hidden: int = 0):
        self.labels, self.r, self.ks, self.makes, self.hidden = labels, r, ks, makes, hidden
        self.rows = np.zeros((len(makes), parts, dof, r + len(labels) + hidden))
        self.g = np.zeros((len(makes), parts, dof))

    def of_block(self, piece) -> tuple:
        """(parts the piece touches, its sums there): to be added()."""
        own = Swaps(self.labels, self.r, self.rows.shape[1], self.rows.shape[2], self.ks, self.makes, self.hidden)
        own.add(piece)
        at = touched(piece)
        return at, own.rows[:, at], own.g[:, at]

    def added(self, at, rows, g) -> None:
        self.rows[:, at] += rows
        self.g[:, at] += g

    def add(self, piece) -> None:
        values = [make(piece) for make in self.makes]
        for k in self.ks:
            j = self.labels[k][1]
            local, idx = local_columns(self.labels, self.r, j, self.hidden)
            F = label_design(piece, self.labels, j, local, self.hidden)
            C = np.column_stack([v[:, j] for v in values])
            for p, sl in segments(piece.part):
                cross = np.vstack([(C[sl].T @ piece.Yj[j][sl]).T, F[sl].T @ C[sl]])  # (columns, variants): as gram
                cross[self.r + local.index(k)] = (C[sl] ** 2).sum(axis=0)
                self.rows[:, p, j, idx] += cross.T
                self.g[:, p, j] += C[sl].T @ piece.tau[sl, j]

    def normals(self, base: Normal) -> list:
        outs = []
        for v in range(len(self.makes)):
            out = base._with(base.G.copy(), base.g.copy())
            for k in self.ks:
                j, i = self.labels[k][1], self.r + k
                out.G[:, j, i, :] = out.G[:, j, :, i] = self.rows[v, :, j]
                out.g[:, j, i] = self.g[v, :, j]
            outs.append(out)
        return outs


def solve_unconstrained(G, g, weak: float = WEAK) -> np.ndarray:
    """Least squares on unit-norm columns, cut at weak^2 of the largest eigenvalue (unexcited: no value)."""
    scale = np.sqrt(np.maximum(np.diag(G), 1e-300))
    ev, V = np.linalg.eigh(G / np.outer(scale, scale))
    keep = ev > weak ** 2 * ev[-1]
    return (V[:, keep] @ ((V[:, keep].T @ (g / scale)) / ev[keep])) / scale
