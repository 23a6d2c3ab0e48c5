"""The inertia regressor Y_m in factored form: O(n^2) motion vectors and one bilinear form.

With zero velocity and no gravity, a unit acceleration of joint j gives link i (i >= j) the
angular acceleration w and the linear acceleration v of O_i (frame i): S_j^i = (w, v), the
column j of link i's Jacobian (newton_euler.Chain.unit_accelerations). The kinetic energy
of link i is 1/2 (m v.v + 2 v.(w x h) + w^T J w) with h = m c and J about O_i, so entry
M[j][k] of the inertia matrix is, over link i's standard parameters (m, mx, my, mz, XX, XY,
XZ, YY, YZ, ZZ),

    m:  v_j . v_k        h:  v_j x w_k + v_k x w_j        J:  the coefficients of w_j^T J w_k

summed over the links i >= max(j, k). Entry (M[j][k], parameter t of link i) of Y_m is that
form, phi_t(S_j^i, S_k^i), and zero when i < max(j, k). Written once here, for any numbers
with + and * (SymPy symbols when C is printed, field elements or mpmath in checks).
"""

from __future__ import annotations

from ..parameters import PER_LINK

KIND_NAMES = ("m", "mx", "my", "mz", "XX", "XY", "XZ", "YY", "YZ", "ZZ")
_INERTIA_AXES = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))  # XX, XY, XZ, YY, YZ, ZZ


def phi(kind: int, a, b):
    """Y_m's entry for standard parameter `kind` (0..9 within a link) from the motions
    a = S_j = (w0, w1, w2, v0, v1, v2) and b = S_k of the same link."""
    wa, va, wb, vb = a[:3], a[3:], b[:3], b[3:]
    if kind == 0:
        return va[0] * vb[0] + va[1] * vb[1] + va[2] * vb[2]
    if kind <= 3:  # component x, y, z of v_j x w_k + v_k x w_j
        r = kind - 1
        p, q = (r + 1) % 3, (r + 2) % 3
        return va[p] * wb[q] - va[q] * wb[p] + vb[p] * wa[q] - vb[q] * wa[p]
    r, c = _INERTIA_AXES[kind - 4]
    return wa[r] * wb[c] if r == c else wa[r] * wb[c] + wa[c] * wb[r]


def stacked_row(j: int, k: int, n: int) -> int:
    """Row of M[j][k] (j <= k) in the stacked upper triangle M11, M12, ..., MNN."""
    return j * n - j * (j - 1) // 2 + (k - j)


def motion_index(i: int, j: int) -> int:
    """Position of S_j^i (j <= i) in the link-major list S_0^0, S_0^1, S_1^1, S_0^2, ..."""
    return i * (i + 1) // 2 + j


def column_links_and_kinds(pivots) -> tuple[list[int], list[int]]:
    """The link (0-based) and parameter kind of each base column (a pivot index into s)."""
    return [p // PER_LINK for p in pivots], [p % PER_LINK for p in pivots]


def pairs(link: int) -> int:
    """How many entries M[j][k], j <= k <= link, a column of this link fills."""
    return (link + 1) * (link + 2) // 2


def stacked_regressor(S, pivots, n: int, zero=0) -> list:
    """Y_m (n(n+1)/2 x len(pivots), row-major) from the link-major motions S (6 numbers each):
    what the emitted loop computes, written plainly for checks."""
    links, kinds = column_links_and_kinds(pivots)
    cols = len(pivots)
    Y = [zero] * (n * (n + 1) // 2 * cols)
    for c, (i, kind) in enumerate(zip(links, kinds)):
        for j in range(i + 1):
            for k in range(j, i + 1):
                Y[stacked_row(j, k, n) * cols + c] = phi(kind, S[motion_index(i, j)], S[motion_index(i, k)])
    return Y
