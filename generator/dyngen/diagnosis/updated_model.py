"""The updated model: effects.yaml (every selected effect, and per joint the vector of the generated
`<robot>_friction`) and the per-joint simulator terms of the URDF and MJCF exports; a payload is
added to the last link, other effects stay in the YAML."""

from __future__ import annotations

import numpy as np

from ..parameters import PER_LINK, dynamic_from_standard, standard_from_dynamic
from ..terms import effect_class
from ..terms.friction import FRICTION_NAMES  # the emitted <robot>_friction's vector, per joint
from ..terms.simple_model import NAMES, VELOCITY
from .joints import COMPLETED, SIMPLE, TIED


def friction_vector(diagnosis, sign_velocity: float) -> np.ndarray:
    """f for <robot>_friction: the laws as fitted, velocity scales included (signs at sign_velocity)."""
    f = np.zeros((diagnosis.joints, len(FRICTION_NAMES)))
    for name in ("vc", "es", "ed"):
        f[:, FRICTION_NAMES.index(name)] = sign_velocity
    for e in diagnosis.selected:
        for name, value in effect_class(e.effect).friction_terms(e.values, e.variant).items():
            f[e.joints[0] - 1, FRICTION_NAMES.index(name)] = value
    return f.ravel()


def joint_dynamics(diagnosis) -> list[dict]:
    """Per joint {"damping", "friction", "armature"} for the exports (each effect's `simulator`)."""
    out = [{} for _ in range(diagnosis.joints)]
    for e in diagnosis.selected:
        simulator = effect_class(e.effect).simulator
        if simulator:
            key, value = simulator
            out[e.joints[0] - 1][key] = float(e.values[value])
    return out


def with_payload(diagnosis, p: np.ndarray) -> np.ndarray:
    """Link parameters with what selected effects add to the last link (a determined payload)."""
    s = None
    for e in diagnosis.selected:
        added = effect_class(e.effect).last_link(e.values, e.variant)
        if added is not None:
            s = standard_from_dynamic(p) if s is None else s
            s[-PER_LINK:] += added
    return np.asarray(p, dtype=float) if s is None else dynamic_from_standard(s)


def effects_yaml(diagnosis, sources: dict, sign_velocity: float) -> str:
    import yaml

    f = friction_vector(diagnosis, sign_velocity).reshape(diagnosis.joints, -1)
    doc = {
        "robot": diagnosis.robot,
        "parameters": sources.get("params"),
        "effects": [{"effect": e.effect, "joints": list(e.joints), **({"variant": e.variant} if e.variant else {}),
                     "values": e.values, "std": e.std, "units": e.units} for e in diagnosis.selected],
        "friction": {"layout": "per joint: " + ", ".join(FRICTION_NAMES) + " (generated <robot>_friction)",
                     "f": [[float(x) for x in row] for row in f]},
    }
    modes = list(enumerate(diagnosis.joint_models, start=1))
    replaces = {j: dict(zip(NAMES, map(float, diagnosis.simple_values[j - 1])))
                for j, m in modes if m in (SIMPLE, TIED)}
    added = {j: dict(zip(NAMES, map(float, diagnosis.completed[j][-len(NAMES):])))
             for j, m in modes if m == COMPLETED and j in diagnosis.completed}
    if replaces or added:
        doc["simple_model"] = {
            "law": f"b + Fc tanh(qd / {VELOCITY:g}) + Fv qd (diagnosis.json joint_models says why, per joint)",
            **({"replaces_effects": replaces} if replaces else {}),  # the joint's torque is this law alone
            **({"added_to_effects": added} if added else {})}  # this law on top of the effects on the joint
    head = (f"# Unmodelled effects of {diagnosis.robot} selected by `dyngen diagnose` (on selection data).\n"
            "# tau = rnea(q, qd, qdd, s) + friction(qd, f) + the other effects listed here.\n")
    return head + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120)
