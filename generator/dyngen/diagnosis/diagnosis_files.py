"""Write a diagnosis: report.md, diagnosis.json, effects.yaml, the figures, the URDF and MJCF with
the selected friction where the links are consistent, and consistent/ where they were found off;
or, when the data cannot support one, what shows why (write_unusable)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..atomic import write_figure, write_file
from . import reidentify, report_text, updated_model


def write_outputs(diagnosis, robot, p, out_dir, sources: dict, sign_velocity: float) -> dict:
    out = Path(out_dir)
    texts = {"report.md": report_text.markdown(diagnosis, sources),
             "diagnosis.json": report_text.to_json(diagnosis, sources),
             "effects.yaml": updated_model.effects_yaml(diagnosis, sources, sign_velocity)}
    paths = {}
    for name, text in texts.items():  # every text is built before the first is written
        write_file(out / name, text)
        paths[name] = out / name
    from .residual_figures import figures

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
    paths.update({f"consistent/{path.name}": path for path in write_all(robot, c.p, folder, c.joint_dynamics())})
    return paths


FIGURE = "conditioning.png"


def _figure(record, path: Path) -> Path:
    """conditioning.png: per joint the measured torque's RMS beside each trial's nominal residual."""
    from .residual_figures import plt  # with the Agg backend

    trials = record.trials
    n = trials[0].torque.size
    fig, ax = plt.subplots(figsize=(10, 4))
    width = 0.8 / (len(trials) + 1)
    x = np.arange(n)
    ax.bar(x, trials[0].torque, width, color="black", label="measured torque")
    for k, t in enumerate(trials):
        ax.bar(x + (k + 1) * width, t.residual, width, label=f"nominal residual: {t.how[:60]}")
    ax.set_yscale("log")
    ax.set_xticks(x + 0.4 - width / 2, [f"J{j + 1}" for j in range(n)])
    ax.set_ylabel("RMS [Nm]")
    ax.set_title(f"{record.recording}: the nominal residual against the measured torque")
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    out = write_figure(path, fig, 110)
    plt.close(fig)
    return out


def write_unusable(err, out_dir, sources: dict) -> dict:
    """When the data cannot support a diagnosis (data/trust.Unusable): report.md, diagnosis.json and the figure."""
    out = Path(out_dir)
    lines = ["# Diagnosis not possible: the data do not support one", "", f"**{err.line}**", "",
             f"![the nominal residual against the torque]({FIGURE})", ""]
    doc = {"schema": report_text.SCHEMA_VERSION, "usable": False, "reason": err.line, **sources, "recordings": []}
    for r in err.recordings:
        lines += [f"## {r.recording}", "", "| conditioning | cutoff [Hz] | " + " | ".join(
            f"J{j + 1}" for j in range(r.trials[0].torque.size)) + " |",
                  "|---|---:|" + "---:|" * r.trials[0].torque.size,
                  "| measured torque RMS | | " + " | ".join(f"{v:.3g}" for v in r.trials[0].torque) + " |"]
        if r.trials[0].scale is not None:
            lines.append("| measured / nominal torque (least squares) | | "
                         + " | ".join(f"{v:.3g}" for v in r.trials[0].scale) + " |")
        for t in r.trials:
            cut = "none" if t.cutoff is None else f"{t.cutoff:.3g}"
            lines.append(f"| {t.how} | {cut} | " + " | ".join(f"{v:.3g}" for v in t.residual) + " |")
        lines.append("")
        doc["recordings"].append({"recording": r.recording, "torque_rms": r.trials[0].torque.tolist(),
                                  "trials": [{"how": t.how, "cutoff": t.cutoff, "residual_rms": t.residual.tolist()}
                                             for t in r.trials]})
    lines += ["Nothing is claimed from these data. The nominal model's residual is larger than the torque it should "
              "explain: differentiation noise (a logger's repeated or late rows, recorded accelerations that are "
              "noise), torques that do not belong to the positions, or a torque in other units or of the other sign "
              "(the ratio row). See docs/measured-data.md (logs as loggers "
              "write them).", ""]
    write_file(out / "report.md", "\n".join(lines))
    write_file(out / "diagnosis.json", json.dumps(doc, indent=1) + "\n")
    figure = _figure(err.recordings[0], out / FIGURE)
    return {"report.md": out / "report.md", "diagnosis.json": out / "diagnosis.json", FIGURE: figure}
