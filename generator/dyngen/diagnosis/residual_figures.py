"""The paper's Figs. 4 and 5 (PNG): measured against model torque, and the residual before and after
the selected effects, on the judged data, reversals and standstill shaded."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..atomic import write_figure  # noqa: E402

from . import phases  # noqa: E402

DPI = 110
MAX_POINTS = 4000  # samples drawn per curve (more only slow the drawing; a screen shows fewer)
SHADED = {"reversal": "tab:orange", "standstill": "0.75"}


def _shade(ax, t, mask, color):
    if not mask.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    for start, stop in zip(edges[::2], edges[1::2]):
        ax.axvspan(t[start], t[min(stop, t.size - 1)], color=color, alpha=0.18, lw=0)


def _save(fig, path, title) -> Path:
    fig.suptitle(title, fontsize=12)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    path = write_figure(path, fig, DPI)
    plt.close(fig)
    return path


def figures(d, out_dir, robot_name: str) -> dict:
    """torques.png and residuals.png of the first judged segment (test data, else selection data)."""
    role = "test" if d.judged_on == "test" else "select"
    seg = next(s for s in d.segments if getattr(s, role).any())
    m = np.flatnonzero(getattr(seg, role))
    label = "test data" if role == "test" else "selection data (no test data given)"
    m = m[::max(1, m.size // MAX_POINTS)]
    t = seg.signals.t[m]
    measured, model = seg.signals.tau[m], seg.tau_model[m]
    before, after = seg.residual[m], seg.residual[m] - seg.correction[m]
    labels = phases.labels(t, seg.signals.q[m], seg.signals.qd[m], seg.signals.qdd[m])
    n = measured.shape[1]
    out = Path(out_dir)

    def torques(ax, j) -> str:
        ax.plot(t, measured[:, j], color="tab:blue", lw=1.4, label="measured")
        ax.plot(t, model[:, j], color="tab:red", lw=1.0, ls="--", label="model (Newton-Euler)")
        ax.plot(t, model[:, j] + seg.correction[m][:, j], color="tab:green", lw=0.9, label="model + selected effects")
        return f"joint {j + 1}"

    def residuals(ax, j) -> str:
        ax.plot(t, before[:, j], color="tab:red", lw=1.0, label="residual, nominal model")
        ax.plot(t, after[:, j], color="tab:green", lw=1.0, label="residual with the selected effects")
        ax.axhline(0, color="0.3", lw=0.6)
        rms_b, rms_a = np.sqrt(np.mean(before[:, j] ** 2)), np.sqrt(np.mean(after[:, j] ** 2))
        return f"joint {j + 1}: RMS {rms_b:.3f} -> {rms_a:.3f}"

    shown = f"{label} ({seg.signals.name})"
    return {"torques": _save(_panels(n, t, labels, torques, "torque [Nm]"), out / "torques.png",
                             f"{robot_name}: measured and model torques on {shown}"),
            "residuals": _save(_panels(n, t, labels, residuals, "residual [Nm]"), out / "residuals.png",
                               f"{robot_name}: residual tau_measured - tau_model on {shown}")}


def _panels(n, t, labels, draw, ylabel):
    """One panel per joint (two columns), reversals and standstill shaded; draw(ax, j) plots joint j and
    returns its title."""
    rows = (n + 1) // 2
    fig, axes = plt.subplots(rows, 2, figsize=(12, 2.2 * rows + 1.0), sharex=True, squeeze=False)
    axes = axes.ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    for j in range(n):
        ax = axes[j]
        for name, color in SHADED.items():
            _shade(ax, t, labels[name][:, j], color)
        ax.set_title(draw(ax, j), loc="left", fontsize=10)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    _legend(fig, axes[0])
    return fig


def _legend(fig, ax):
    handles, names = ax.get_legend_handles_labels()
    for name, color in SHADED.items():
        handles.append(plt.Rectangle((0, 0), 1, 1, color=color, alpha=0.3))
        names.append(f"{name} (shaded)")
    fig.legend(handles, names, loc="upper center", ncol=len(handles), frameon=False, bbox_to_anchor=(0.5, 0.965),
               fontsize=8)
    visible = [a for a in fig.axes if a.get_visible()]
    for col in (0, 1):  # the lowest visible panel of each column carries the time axis
        column = [a for a in visible if a.get_subplotspec().colspan.start == col]
        if column:
            column[-1].set_xlabel("time [s]")
            column[-1].xaxis.set_tick_params(labelbottom=True)
