"""Figures of the validation (PNG, matplotlib Agg): the trajectory (paper Fig. 3) and the
torque comparison (paper Fig. 6)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..atomic import write_figure  # noqa: E402

DPI = 120


def _colors(n: int):
    cmap = plt.get_cmap("tab10")
    return [cmap(j % 10) for j in range(n)]


def _knot_lines(ax, knot_times):
    for tk in knot_times if knot_times is not None else ():
        ax.axvline(tk, color="0.6", lw=0.6, ls=":", zorder=0)


def _groups(*arrays) -> list[list[int]]:
    """Joints whose curves coincide in every array (drawn once, labelled with all their numbers)."""
    n = arrays[0].shape[1]
    groups, seen = [], set()
    for j in range(n):
        if j in seen:
            continue
        same = [k for k in range(j, n) if k not in seen
                and all(np.array_equal(a[:, j], a[:, k]) for a in arrays)]
        seen.update(same)
        groups.append(same)
    return groups


def trajectory_figure(t, q, qd, qdd, path, knot_times=None, title="Joint trajectory (Table V)") -> Path:
    """Position, velocity and acceleration of every joint, three stacked panels (paper Fig. 3).

    Joints with identical curves over the whole trajectory are drawn once, labelled with all
    their numbers (in Table V: joints 1, 3, 5, 7 and joints 2, 4, 6)."""
    t, q, qd, qdd = (np.asarray(x, dtype=float) for x in (t, q, qd, qdd))
    groups = _groups(q, qd, qdd)
    colors = _colors(q.shape[1])
    fig, axes = plt.subplots(3, 1, figsize=(10, 8.5), sharex=True)
    panels = [(q, "position [rad]", "Position"), (qd, "velocity [rad/s]", "Velocity"),
              (qdd, "acceleration [rad/s$^2$]", "Acceleration")]
    for ax, (data, ylabel, name) in zip(axes, panels):
        _knot_lines(ax, knot_times)
        for g in groups:
            label = f"joint {g[0] + 1}" if len(g) == 1 else "joints " + ", ".join(str(k + 1) for k in g)
            ax.plot(t, data[:, g[0]], color=colors[g[0]], lw=1.5, label=label)
        ax.set_ylabel(ylabel)
        ax.set_title(name, fontsize=10, loc="left")
        ax.grid(True, alpha=0.3)
        ax.set_xlim(t[0], t[-1])
    axes[-1].set_xlabel("time [s]")
    handles, labels = axes[0].get_legend_handles_labels()
    if knot_times is not None:
        handles.append(plt.Line2D([], [], color="0.6", lw=0.8, ls=":"))
        labels.append("knots")
    fig.legend(handles, labels, loc="upper center", ncol=len(handles), frameon=False, bbox_to_anchor=(0.5, 0.955))
    fig.suptitle(title, fontsize=12, y=0.99)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    path = write_figure(path, fig, DPI)
    plt.close(fig)
    return path


def torque_comparison_figure(t, tau_ne, tau_coeff, path, knot_times=None,
                             labels=("Newton-Euler, extracted parameters", "Lagrangian, identified coefficients"),
                             title="Joint torques along the Table V trajectory") -> Path:
    """One panel per joint with both torques (paper Fig. 6), and a last panel with their difference."""
    t, a, b = (np.asarray(x, dtype=float) for x in (t, tau_ne, tau_coeff))
    n = a.shape[1]
    cols = 2
    rows = (n + 1 + cols - 1) // cols  # n joints + the difference panel
    fig, axes = plt.subplots(rows, cols, figsize=(12, 2.3 * rows + 0.9), sharex=True, squeeze=False)
    axes = axes.ravel()
    for j in range(n):
        ax = axes[j]
        _knot_lines(ax, knot_times)
        ax.plot(t, a[:, j], color="tab:blue", lw=2.2, label=labels[0])
        ax.plot(t, b[:, j], color="tab:green", lw=1.2, ls=(0, (4, 3)), label=labels[1])
        ax.set_title(f"joint {j + 1}", fontsize=10, loc="left")
        ax.set_ylabel("torque [Nm]")
        ax.grid(True, alpha=0.3)
    ax = axes[n]
    _knot_lines(ax, knot_times)
    for j, color in enumerate(_colors(n)):
        ax.plot(t, a[:, j] - b[:, j], color=color, lw=1.0, label=f"J{j + 1}")
    ax.set_title("difference (blue \u2212 green)", fontsize=10, loc="left")
    ax.set_ylabel("torque [Nm]")
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
    ax.grid(True, alpha=0.3)
    ax.legend(title=None, ncol=n, fontsize=7, loc="lower right", bbox_to_anchor=(1.0, 1.0), frameon=False,
              handlelength=1.2, columnspacing=0.8, handletextpad=0.4, borderaxespad=0.1)
    for ax in axes[n + 1:]:
        ax.set_visible(False)
    for c in range(cols):  # the lowest visible panel of each column carries the time axis
        lowest = max(k for k in range(c, n + 1, cols))
        axes[lowest].set_xlabel("time [s]")
        axes[lowest].xaxis.set_tick_params(labelbottom=True)
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="upper center", ncol=2, frameon=False, bbox_to_anchor=(0.5, 0.965))
    fig.suptitle(title, fontsize=12, y=0.995)
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    for ax in axes[:n + 1]:
        ax.set_xlim(t[0], t[-1])
    path = write_figure(path, fig, DPI)
    plt.close(fig)
    return path
