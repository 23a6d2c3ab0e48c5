"""What an extraction found, as text and as YAML that a simulator set-up can read."""

from __future__ import annotations

import numpy as np

from ..parameters import PER_LINK, consistency_margin
from .problem import pinned


def links_yaml(p) -> str:
    """The parameters in the `parameters.nominal` format of docs/conventions.md."""
    lines = []
    for i, link in enumerate(np.asarray(p).reshape(-1, PER_LINK)):
        c = ", ".join(f"{x:.10g}" for x in link[1:4])
        inertia = ", ".join(f"{x:.10g}" for x in link[4:10])
        lines.append(f"  - {{m: {link[0]:.10g}, c: [{c}], I: [{inertia}]}}   # link {i + 1}")
    return "\n".join(lines) + "\n"


UNREACHABLE = 1e-2  # relative coefficient residual above which the targets count as unreachable


def unreachable(robot, extraction, threshold: float = UNREACHABLE, top: int = 6) -> list[str]:
    """Warnings, first thing in the summary and the files, when no consistent parameters come near
    the identified coefficients: the relative residual of a kind above `threshold`, the coefficients
    missed most (target and the closest consistent value) and the parameters pinned at a bound.
    "N/N restarts consistent" alone is not a success."""
    lines = []
    for kind, r in (extraction.stages[-1].residuals or {}).items():
        t = extraction.targets[kind]
        rel = float(np.linalg.norm(r) / max(np.linalg.norm(t.v), 1e-300))
        if rel <= threshold:
            continue
        worst = [k for k in np.argsort(-np.abs(r))[:top] if abs(r[k]) >= 0.1 * np.max(np.abs(r))]
        missed = ", ".join(f"{robot.identified[kind][k].coefficient} = {t.v[k]:.4g} (closest consistent "
                           f"{t.v[k] + r[k]:.4g})" for k in worst)
        lines.append(f"WARNING: the identified {kind} coefficients are not reachable by physically consistent "
                     f"parameters within the bounds: relative residual {rel:.2g}. Cannot be met: {missed}.")
    if lines:
        at = pinned(extraction.problem, extraction.p)
        if at:
            lines.append(f"WARNING: parameters pinned at a bound: {', '.join(at)}.")
        lines.append("WARNING: these coefficients are not a consistent robot (typically least squares on data that "
                     "do not excite them, or unmodelled friction and offsets pushed into them); identify from the "
                     "recordings with `dyngen identify ROBOT.yaml --data ...` (physically consistent, with friction) "
                     "instead of extracting from them.")
    return lines


def extracted_yaml(robot, extraction, options, seconds: float) -> str:
    last = extraction.stages[-1]
    head = [f"# {line}" for line in unreachable(robot, extraction)] + [
        f"# Link parameters of {robot.name} extracted by dyngen from {robot.source}:",
        f"# procedure {options.procedure}, {options.restarts} restarts, seed {options.seed}, "
        f"consistency margin {options.margin:g} kg m^2.",
        "# m [kg]; c [m] in link frame i; I [kg m^2] about the centre of mass, axes of frame i,",
        "# order xx, xy, xz, yy, yz, zz (docs/conventions.md).",
        f"robot: {robot.name}",
        f"cost: {last.cost!r}   # sum of squared coefficient residuals",
        "residuals:",
    ]
    for kind, r in (last.residuals or {}).items():
        head.append(f"  {kind}: [{', '.join(f'{x:.3e}' for x in r)}]")
    head.append("links:")
    return "\n".join(head) + "\n" + links_yaml(extraction.p)


def consistency_table(columns: dict) -> str:
    """columns: label -> p (10N). One row per link: mass and lambda_min(tr(I)/2 E - I), 'ok' or 'NO'."""
    labels = list(columns)
    n = len(next(iter(columns.values()))) // PER_LINK
    header = "link | " + " | ".join(f"{label}: m [kg], lambda_min [kg m^2]" for label in labels)
    rows = [header, "---|" + "---|" * len(labels)]
    for link in range(n):
        cells = []
        for label in labels:
            row = np.asarray(columns[label]).reshape(-1, PER_LINK)[link]
            lam = consistency_margin(row)
            cells.append(f"{row[0]:.4f}, {lam:+.2e} {'ok' if row[0] > 0 and lam >= 0 else 'NO'}")
        rows.append(f"{link + 1} | " + " | ".join(cells))
    return "\n".join(rows)


def summary(robot, extraction, options, seconds: float) -> str:
    lines = unreachable(robot, extraction) + [f"extraction of {robot.name}: procedure {options.procedure}, {options.restarts} restarts, "
             f"seed {options.seed}, {seconds:.1f} s"]
    for s in extraction.stages:
        lines.append(f"  stage {s.name}: {s.consistent}/{s.restarts} restarts consistent, "
                     f"cost {s.cost:.3e} (best fit {s.fit_cost:.3e})")
    for kind, r in (extraction.stages[-1].residuals or {}).items():
        t = extraction.targets[kind]
        rel = np.linalg.norm(r) / max(np.linalg.norm(t.v), 1e-300)
        worst = int(np.argmax(np.abs(r)))
        lines.append(f"  {kind} coefficients: |residual| {np.linalg.norm(r):.3e} (relative {rel:.2e}); "
                     f"largest at {robot.identified[kind][worst].coefficient} = {r[worst]:+.2e}")
    return "\n".join(lines)


def residual_comparison(robot, extraction, columns: dict, folder, top: int = 4) -> list[str]:
    """The coefficients dyngen's parameters miss most, with every compared solution's residual there."""
    from ..runtime import load

    if len(columns) < 2:
        return []
    model = load(folder)
    rows = []
    for kind, target in extraction.targets.items():
        residual = {label: target.W @ model(f"pi_{kind}", p) - target.v for label, p in columns.items()}
        ours = residual["dyngen"]
        for k in np.argsort(-np.abs(ours))[:top]:
            cells = ", ".join(f"{label} {r[k]:+.2e}" for label, r in residual.items())
            rows.append(f"{kind}: {robot.identified[kind][k].coefficient}: {cells}")
    return rows
