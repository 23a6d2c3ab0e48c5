"""Validation as in the paper's Sec. IV (Gaz, Flacco, De Luca, ICRA 2016).

Along the Table V trajectory (7 rest-to-rest cubics through 8 knots), the joint torques of
the Newton-Euler routine with the extracted link parameters are compared with those of the
Lagrangian model built from the identified coefficients alone (the paper's Fig. 6):

    result = validate("examples/lwr.yaml", "generated/lwr", ex.p, pi_g_hat, pi_m_hat, "out/validation")

writes trajectory.png (Fig. 3), torques.png (Fig. 6) and validation.md, and returns the
per-joint differences. Modules: trajectory (cubic_through_knots, TABLE_V), torques
(newton_euler, from_coefficients, compare), figures (trajectory_figure, torque_comparison_figure).
"""

from __future__ import annotations

from pathlib import Path


from .torques import compare, from_coefficients, newton_euler
from .trajectory import TABLE_V, TABLE_V_KNOTS, TABLE_V_TIMES, cubic_through_knots, table_v

__all__ = ["validate", "markdown_table", "cubic_through_knots", "table_v", "TABLE_V", "TABLE_V_KNOTS",
           "TABLE_V_TIMES", "newton_euler", "from_coefficients", "compare"]


def _robot_name(robot) -> str:
    if isinstance(robot, (str, Path)):
        from ..description import load_robot
        robot = load_robot(robot)
    return robot.name


def markdown_table(result: dict, name: str, parameters_label: str = "extracted parameters") -> str:
    lines = [f"# {name}: Newton-Euler ({parameters_label}) vs identified coefficients", "",
             f"Trajectory: Table V ({result['samples']} samples at {result['rate_hz']:g} Hz, "
             f"{result['duration']:g} s). Difference = Newton-Euler with the {parameters_label} "
             "minus the Lagrangian model from the identified coefficients (pi_g, pi_m).", "",
             "| joint | max abs difference [Nm] | RMS difference [Nm] | peak torque [Nm] | max / peak |",
             "|---|---|---|---|---|"]
    for j, (mx, rms, peak) in enumerate(zip(result["max_abs"], result["rms"], result["peak"])):
        lines.append(f"| {j + 1} | {mx:.3e} | {rms:.3e} | {peak:.3f} | {mx / peak if peak else float('nan'):.2e} |")
    lines += ["", f"Largest difference: {max(result['max_abs']):.3e} Nm.", "",
              "Figures: trajectory.png (position, velocity, acceleration), torques.png (both torques per joint "
              "and their difference).", ""]
    return "\n".join(lines)


def validate(robot, folder, p_extracted, pi_g_hat, pi_m_hat, out_dir, rate_hz: float = 100.0,
             model=None, derivative: str = "exact", parameters_label: str = "extracted parameters") -> dict:
    """The Sec. IV validation on the Table V trajectory.

    robot: YAML path or Robot (for its name); folder: the generated C folder (loaded with
    dyngen.runtime.load unless model is given); p_extracted: dynamic parameters (10N);
    pi_g_hat, pi_m_hat: identified gravity and inertia coefficients in dyngen's basis
    (solve(W, v) of the extraction targets). Writes out_dir/trajectory.png, torques.png,
    validation.md. Returns {"max_abs", "rms", "peak": per-joint lists [Nm] (max |difference|,
    RMS difference, max |coefficients torque|), "samples", "rate_hz", "duration",
    "paths": {"trajectory", "torques", "markdown": Path}, "torques": {"t", "newton_euler",
    "coefficients": arrays}}. parameters_label names p_extracted in the
    figure and the table (e.g. "V-REP nominal parameters" when validating other parameters).
    """
    from . import figures
    name = _robot_name(robot)
    if model is None:
        from ..runtime import load
        model = load(folder)
    n = int(model.manifest["dof"])
    if n != TABLE_V_KNOTS.shape[1]:
        raise ValueError(f"{name}: the Table V trajectory is for 7 joints, the model has {n}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t, q, qd, qdd = table_v(rate_hz)
    tau_ne = newton_euler(model, p_extracted, q, qd, qdd)
    tau_coeff = from_coefficients(model, pi_g_hat, pi_m_hat, q, qd, qdd, derivative)
    diff = compare(tau_ne, tau_coeff)
    paths = {
        "trajectory": figures.trajectory_figure(t, q, qd, qdd, out / "trajectory.png", knot_times=TABLE_V_TIMES,
                                                title=f"{name}: joint trajectory of Table V (7 cubics, 8 knots)"),
        "torques": figures.torque_comparison_figure(t, tau_ne, tau_coeff, out / "torques.png",
                                                    knot_times=TABLE_V_TIMES,
                                                    labels=(f"Newton-Euler, {parameters_label}",
                                                            "Lagrangian, identified coefficients"),
                                                    title=f"{name}: joint torques along the Table V trajectory"),
    }
    result = {key: [float(x) for x in value] for key, value in diff.items()}
    result.update(samples=int(t.size), rate_hz=float(rate_hz), duration=float(t[-1] - t[0]))
    paths["markdown"] = out / "validation.md"
    paths["markdown"].write_text(markdown_table(result, name, parameters_label))
    result["paths"] = paths
    result["torques"] = {"t": t, "newton_euler": tau_ne, "coefficients": tau_coeff}
    return result
