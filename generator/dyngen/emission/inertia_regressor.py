"""C of the base inertia regressor Y_m(q): O(n^2) code for an output with O(n^3) entries.

Straight-line code computes the motions S_j^i of every link under a unit acceleration of
every joint (derivation/inertia.py) into a local array, link by link; a short loop then
fills Y_m, driven by two small tables (local, not static: the library has no static
data at all, tests/test_cli.py) that give each base column's link and parameter kind:
entry (M[j][k], column c) is phi_kind(S_j, S_k) of link(c) for j <= k <= link(c), else 0.
Printing every entry of Y_m instead made its code, and every step that touched it
(derivation, reduction, printing, compiling), grow like n^3. The switch on the kind sits
outside the loops over (j, k): inside them it made the LWR's Y_m 2.2x slower (1692 vs 697
ns per call, gcc -O2); as written it is faster than the old straight-line code (779 ns).

Operation counts: the straight-line part as printed, plus each column's trip count times
its loop body's floating-point operations (index arithmetic is not counted).
"""

from __future__ import annotations

import sympy as sp

from ..derivation.inertia import KIND_NAMES, column_links_and_kinds, pairs, phi
from .c_code import CFunction, Printer, straight_line
from .opcount import OpCount, count, count_all

MOTION_ARGS = (sp.symbols("a0:6", real=True), sp.symbols("b0:6", real=True))  # S_j and S_k in the loops


def render_inertia_regressor(prefix: str, joint_models, motions, base, doc: str) -> CFunction:
    """motions: the unit_accelerations Model (Derivation.unit_accelerations); base: the
    inertia BaseSet (its pivots are the columns of Y_m kept)."""
    n = len(joint_models)
    n_stacked, rank = n * (n + 1) // 2, base.rank
    real = f"{prefix}_real"
    code = straight_line(prefix, joint_models, motions, motions.outputs)
    body = code.body + [
        "/* S[i(i+1)/2 + j]: angular and linear acceleration of link i+1 (frame i+1, at its origin)",
        " * when joint j+1 accelerates at 1 and nothing else moves (no gravity) */",
        f"const {real} S[{len(motions.outputs) // 6}][6] = {{"]
    for i in range(n):
        body.append(f"    /* link {i + 1} */")
        for j in range(i + 1):
            start = 6 * (i * (i + 1) // 2 + j)
            entries = ", ".join(code.printer.doprint(x) for x in motions.outputs[start:start + 6])
            body.append(f"    {{{entries}}},")
    body.append("};")
    links, kinds = column_links_and_kinds(base.pivots)
    body += [
        "/* Y: entry (M[j][k], column c) is phi over S_j, S_k of link column_link[c] for",
        " * j <= k <= column_link[c], else 0; phi by the column's standard parameter (derivation/inertia.py) */",
        f"const unsigned char column_link[{rank}] = {{{', '.join(map(str, links))}}};",
        f"const unsigned char column_kind[{rank}] = {{{', '.join(map(str, kinds))}}};"
        f"  /* {', '.join(f'{k} {name}' for k, name in enumerate(KIND_NAMES))} */",
        f"for (int e = 0; e < {n_stacked * rank}; ++e) Y[e] = 0;",
        f"for (int c = 0; c < {rank}; ++c) {{",
        "    const int i = column_link[c];",
        f"    const {real} (*link)[6] = S + i * (i + 1) / 2;  /* S_0 .. S_i of that link */",
        f"    {real} *y = Y + c;  /* column c: row r is y[r * {rank}] */",
        "    switch (column_kind[c]) {  /* outside the loops: each loop body is branch-free */",
    ]
    names = {s: f"link[{v}][{k}]" for v, group in zip("jk", MOTION_ARGS) for k, s in enumerate(group)}
    printer = Printer(prefix, names)
    for kind in sorted(set(kinds)):
        body += [
            f"    case {kind}:  /* {KIND_NAMES[kind]} */",
            f"        for (int j = 0, row = 0; j <= i; row += {n} - j, ++j)  /* row: M[j][j]'s */",
            "            for (int k = j; k <= i; ++k)",
            f"                y[(row + k - j) * {rank}] = {printer.doprint(phi(kind, *MOTION_ARGS))};",
            "        break;",
        ]
    body += ["    }", "}"]
    loop = OpCount()
    for link, kind in zip(links, kinds):  # trip count times the body's floating-point operations
        trips = pairs(link)
        body_ops = count(phi(kind, *MOTION_ARGS))
        loop = loop + OpCount(trips * body_ops.mul, trips * body_ops.add, trips * body_ops.div)
    ops = code.ops + count_all(motions.outputs) + loop
    doc += " Factored: link motions, then a loop (operation count: trips x loop body)."
    return CFunction(f"{prefix}_regressor_inertia", doc, [("q", n, motions.inputs[0].doc)],
                     ("Y", (n_stacked, rank), "row-major"), body, ops, code.used)
