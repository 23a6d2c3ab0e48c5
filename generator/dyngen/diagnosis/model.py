"""The updated model: the nominal link parameters plus the selected effects, as

- YAML (`effects.yaml`): every selected effect with its values and deviations, and per
  joint the friction vector of the generated `<robot>_friction(qd, f, tau)` routine;
- per-joint simulator terms for URDF (damping, friction) and MJCF (damping, frictionloss,
  armature), written with the nominal links by dyngen.export.

Effects with no place in a simulator file (sensor offset and gain, time shift, tilt,
coefficient errors) stay in the YAML only; a payload is added to the last link.
"""

from __future__ import annotations

import numpy as np

from ..parameters import PER_LINK, dynamic_from_standard, standard_from_dynamic

FRICTION_FIELDS = ("Fc", "Fv", "Fs", "vs", "eps")  # templates/friction.c.j2


def friction_vector(diagnosis, sign_velocity: float) -> np.ndarray:
    """f (5N) for <robot>_friction: Fc, Fv, Fs, vs, eps per joint."""
    f = np.zeros((diagnosis.joints, len(FRICTION_FIELDS)))
    f[:, 4] = sign_velocity
    for e in diagnosis.selected:
        if e["effect"] not in ("coulomb", "viscous", "stribeck"):
            continue
        j = e["joints"][0] - 1
        if e["effect"] == "coulomb":
            f[j, 0] = e["values"]["Fc"]
            f[j, 4] = e["variant"]["vc"]  # the fitted velocity scale (the Stribeck term shares it)
        elif e["effect"] == "viscous":
            f[j, 1] = e["values"]["Fv"]
        else:
            f[j, 2], f[j, 3] = e["values"]["Fs"], e["variant"]["vs"]
    return f.ravel()


def joint_dynamics(diagnosis) -> list[dict]:
    """Per joint {"damping", "friction", "armature"} for the URDF and MJCF exports."""
    out = [{} for _ in range(diagnosis.joints)]
    names = {"coulomb": ("friction", "Fc"), "viscous": ("damping", "Fv"), "armature": ("armature", "Ia")}
    for e in diagnosis.selected:
        if e["effect"] in names:
            key, value = names[e["effect"]]
            out[e["joints"][0] - 1][key] = float(e["values"][value])
    return out


def with_payload(diagnosis, p: np.ndarray) -> np.ndarray:
    """Link parameters with a selected payload added to the last link (if its values are all
    determined); otherwise p unchanged."""
    payload = next((e for e in diagnosis.selected if e["effect"] == "payload"), None)
    if payload is None or None in payload["values"].values():
        return np.asarray(p, dtype=float)
    from .effects.body import standard_of_payload

    s = standard_from_dynamic(p)
    s[-PER_LINK:] += standard_of_payload(payload["values"])
    return dynamic_from_standard(s)


def effects_yaml(diagnosis, sources: dict, sign_velocity: float) -> str:
    import yaml

    f = friction_vector(diagnosis, sign_velocity).reshape(diagnosis.joints, -1)
    from .baseline import NAMES, VELOCITY

    doc = {
        "robot": diagnosis.robot,
        "parameters": sources.get("params"),
        "effects": [{"effect": e["effect"], "joints": e["joints"], **({"variant": e["variant"]} if e["variant"] else {}),
                     "values": e["values"], "std": e["std"], "units": e["units"]} for e in diagnosis.selected],
        "friction": {"layout": "per joint: " + ", ".join(FRICTION_FIELDS) + " (generated <robot>_friction)",
                     "f": [[float(x) for x in row] for row in f]},
    }
    if diagnosis.simple_wins:
        doc["simple_model"] = {
            "law": f"b + Fc tanh(qd / {VELOCITY:g}) + Fv qd, on the joints where it did better than the effects",
            "joints": {j: dict(zip(NAMES, map(float, diagnosis.simple_values[j - 1]))) for j in diagnosis.simple_wins}}
    head = (f"# Unmodelled effects of {diagnosis.robot} selected by `dyngen diagnose` (on selection data).\n"
            "# tau = rnea(q, qd, qdd, s) + friction(qd, f) + the other effects listed here.\n")
    return head + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120)
