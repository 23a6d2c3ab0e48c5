"""Write a diagnosis: report.md, diagnosis.json, effects.yaml, torques.png, residuals.png and,
when the link parameters are physically consistent, <robot>.urdf and <robot>.xml with the
selected friction and rotor inertia."""

from __future__ import annotations

from pathlib import Path

from ..atomic import write_file
from . import model, report


def write_outputs(diagnosis, robot, p, out_dir, sources: dict, sign_velocity: float) -> dict:
    out = Path(out_dir)
    texts = {"report.md": report.markdown(diagnosis, sources),
             "diagnosis.json": report.to_json(diagnosis, sources),
             "effects.yaml": model.effects_yaml(diagnosis, sources, sign_velocity)}
    paths = {}
    for name, text in texts.items():  # every text is built before the first is written
        write_file(out / name, text)
        paths[name] = out / name
    from .figures import figures

    paths.update(figures(diagnosis, out, robot.name))
    if not robot.gravity_symbols:
        from ..export import write_all

        try:
            exported = write_all(robot, model.with_payload(diagnosis, p), out, model.joint_dynamics(diagnosis))
            paths.update({path.name: path for path in exported})
        except ValueError as err:  # e.g. the paper's parameters: not physically consistent
            paths["export skipped"] = str(err)
    return paths
