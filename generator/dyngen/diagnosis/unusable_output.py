"""What `dyngen diagnose` writes when the data cannot support a diagnosis (trust.Unusable): report.md,
diagnosis.json ({"usable": false}) and conditioning.png (torque RMS beside each trial's residual)."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..atomic import write_figure, write_file  # noqa: E402
from .report import SCHEMA_VERSION  # noqa: E402

FIGURE = "conditioning.png"


def _figure(record, path: Path) -> Path:
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
    ax.set_title(f"{record.recording}: the nominal residual exceeds the torque (conditioning cannot be trusted)")
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    out = write_figure(path, fig, 110)
    plt.close(fig)
    return out


def write_unusable(err, out_dir, sources: dict) -> dict:
    out = Path(out_dir)
    lines = ["# Diagnosis not possible: the conditioning cannot be trusted", "", f"**{err.line}**", "",
             f"![the nominal residual against the torque]({FIGURE})", ""]
    doc = {"schema": SCHEMA_VERSION, "usable": False, "reason": err.line, **sources, "recordings": []}
    for r in err.recordings:
        lines += [f"## {r.recording}", "", "| conditioning | cutoff [Hz] | " + " | ".join(
            f"J{j + 1}" for j in range(r.trials[0].torque.size)) + " |",
                  "|---|---:|" + "---:|" * r.trials[0].torque.size,
                  "| measured torque RMS | | " + " | ".join(f"{v:.3g}" for v in r.trials[0].torque) + " |"]
        for t in r.trials:
            cut = "none" if t.cutoff is None else f"{t.cutoff:.3g}"
            lines.append(f"| {t.how} | {cut} | " + " | ".join(f"{v:.3g}" for v in t.residual) + " |")
        lines.append("")
        doc["recordings"].append({"recording": r.recording, "torque_rms": r.trials[0].torque.tolist(),
                                  "trials": [{"how": t.how, "cutoff": t.cutoff, "residual_rms": t.residual.tolist()}
                                             for t in r.trials]})
    lines += ["Nothing is claimed from these data. The nominal model's residual is larger than the torque it should "
              "explain: differentiation noise (a logger's repeated or late rows, recorded accelerations that are "
              "noise) or torques that do not belong to the positions. See docs/measured-data.md (logs as loggers "
              "write them).", ""]
    write_file(out / "report.md", "\n".join(lines))
    write_file(out / "diagnosis.json", json.dumps(doc, indent=1) + "\n")
    figure = _figure(err.recordings[0], out / FIGURE)
    return {"report.md": out / "report.md", "diagnosis.json": out / "diagnosis.json", FIGURE: figure}
