"""Synthetic serial arms for the scaling benchmark: N joints, standard DH, mixed twists
(0, +pi/2, -pi/2), nonzero link lengths a and offsets d, and one prismatic joint.

Nothing here is a real robot; the numbers only have to be generic (no accidental symmetry
that would make an arm cheaper than a real one of the same size), deterministic (the same
YAML every run, so the timings are comparable) and loadable by dyngen.
"""
from __future__ import annotations

# Twists cycle through these so that consecutive axes are parallel, orthogonal one way and
# orthogonal the other way, as on real arms (a run of pi/2 alone would be a special case).
ALPHAS = ("pi/2", "0", "-pi/2", "pi/2", "-pi/2", "0")


def prismatic_index(n: int) -> int:
    """0-based index of the one prismatic joint: the third joint; on a 2-joint arm the first
    (a prismatic second joint would move along the horizontal z1, and an arm whose gravity
    vector is identically zero is not what this benchmark is about)."""
    return 2 if n > 2 else 0


def synthetic_arm_yaml(n: int) -> str:
    """The YAML text of an n-joint synthetic arm named `synthetic<n>`."""
    if n < 2:
        raise ValueError("a synthetic arm needs at least 2 joints")
    lines = [f"# Synthetic {n}-joint arm written by bench/synthetic_arm.py (not a real robot).",
             f"name: synthetic{n}", "dh: standard", "gravity: [0, 0, -9.81]", "joints:"]
    for i in range(n):
        a = round(0.05 + 0.03 * (i % 4), 3)       # 0.05 .. 0.14 m, never zero
        d = round(0.30 - 0.02 * (i % 5), 3)       # 0.22 .. 0.30 m, never zero
        alpha = ALPHAS[i % len(ALPHAS)]
        if i == prismatic_index(n):
            lines.append(f"  - {{type: prismatic, a: {a}, alpha: \"{alpha}\", d: {d}, theta: \"pi/2\", "
                         "limits: {lower: 0.0, upper: 0.5}}")
        else:
            lines.append(f"  - {{type: revolute, a: {a}, alpha: \"{alpha}\", d: {d}, theta: 0, "
                         "limits: {lower: -2.9, upper: 2.9}}")
    return "\n".join(lines) + "\n"
