"""Quantities a reader wants next to the fitted values: tilt angles, the payload's mass and
centre of mass, a gain as a factor, a time shift in milliseconds."""

from __future__ import annotations

import numpy as np

from .effects.tilt import tilt_angles_deg, tilt_axes


def derived(robot, effect: str, values: dict, std: dict) -> dict:
    if effect == "tilt" and None not in values.values():
        a1, a2 = tilt_angles_deg(robot, [values["dg1"], values["dg2"]])
        s1, s2 = tilt_angles_deg(robot, [std["dg1"], std["dg2"]])
        return {"tilt_deg": [a1, a2], "tilt_std_deg": [abs(s1), abs(s2)], "tilt_towards": list(tilt_axes(robot)),
                "tilt_total_deg": float(np.hypot(a1, a2))}
    if effect == "gravity_scale" and values.get("dg") is not None:
        g = float(np.linalg.norm([float(x) for x in robot.gravity]))
        return {"relative": values["dg"] / g}
    if effect == "ripple" and None not in values.values():
        k = len(values) // 2
        return {"amplitude_Nm": [float(np.hypot(values[f"a{h}"], values[f"b{h}"])) for h in range(1, k + 1)]}
    if effect == "payload" and values.get("m") not in (None, 0.0):
        m = values["m"]
        com = [values[k] / m if values.get(k) is not None else None for k in ("mx", "my", "mz")]
        return {"mass_kg": m, "com_m": com}
    if effect == "gain":
        return {"factor": 1.0 + values["k-1"]}
    if effect == "time_shift":
        return {"dt_ms": 1e3 * values["dt"], "dt_std_ms": 1e3 * std["dt"]}
    return {}
