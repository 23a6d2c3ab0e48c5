"""Write a diagnosis: report.md, diagnosis.json, effects.yaml, the figures, the URDF and MJCF with
the selected friction where the links are consistent, and consistent/ where they were found off."""

from __future__ import annotations

from pathlib import Path

from ..atomic import write_file
from . import reidentify, report, updated_model


def write_outputs(diagnosis, robot, p, out_dir, sources: dict, sign_velocity: float) -> dict:
    out = Path(out_dir)
    texts = {"report.md": report.markdown(diagnosis, sources),
             "diagnosis.json": report.to_json(diagnosis, sources),
             "effects.yaml": updated_model.effects_yaml(diagnosis, sources, sign_velocity)}
    paths = {}
    for name, text in texts.items():  # every text is built before the first is written
        write_file(out / name, text)
        paths[name] = out / name
    from .figures import figures

    paths.update(figures(diagnosis, out, robot.name))
    if not robot.gravity_symbols:
        from ..export import write_all

        try:
            exported = write_all(robot, updated_model.with_payload(diagnosis, p), out, updated_model.joint_dynamics(diagnosis))
            paths.update({path.name: path for path in exported})
        except ValueError as err:  # e.g. the paper's parameters: not physically consistent
            paths["export skipped"] = str(err)
    if diagnosis.consistent and diagnosis.reidentified is not None:
        paths.update(_consistent(diagnosis, robot, out / "consistent", sources))
    return paths


def _consistent(diagnosis, robot, folder, sources: dict) -> dict:
    from ..export import write_all
    from ..identification.consistent_output import consistent_table, consistent_yaml, summary_lines

    c = diagnosis.reidentified
    fits = [Path(x).name for x in sources.get("fit", [])]
    yaml = consistent_yaml(robot, c, fits, f"{sources.get('conditioning', 'as conditioned for the diagnosis')}; "
                           f"decimated to about {reidentify.RATE:g} Hz")
    table = (f"# {robot.name}: link parameters re-identified by the diagnosis (consistent, from {', '.join(fits)})\n\n"
             f"Used on joint(s) {', '.join(map(str, diagnosis.consistent.joints))}, where they did better than "
             "every effect and the simple model on selection data.\n\n"
             + "\n".join(summary_lines(robot, c)) + "\n\n" + consistent_table(c) + "\n")
    paths = {}
    for name, text in (("identified.yaml", yaml), ("identified.md", table)):
        write_file(folder / name, text)
        paths[f"consistent/{name}"] = folder / name
    exported = write_all(robot, c.p, folder, c.joint_dynamics())
    paths.update({f"consistent/{path.name}": path for path in exported})
    return paths
