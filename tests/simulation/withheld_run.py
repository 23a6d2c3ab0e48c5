"""One withheld-effect case through the diagnosis as a user runs it, and its verdict.

Fit on one trajectory (selection on blocks of it), test on the other, which plays no other
part; `direction` "forward" fits on the Fourier excitation and tests on Table V, "backward"
the reverse. Conditioning is dyngen's default (data/conditioning.py: automatic for files
without velocity columns). The verdict (withheld_verdict.problems) bounds the test RMS after
by 1.5 x what the perfect model leaves on the same conditioned test data (perfect.py).
"""

from __future__ import annotations

import json
import time

import numpy as np

from dyngen.data import condition, read_recording
from dyngen.diagnosis import diagnose
from dyngen.diagnosis.report_text import to_json

from .perfect import perfect_rms
from .withheld_cases import CASES, COMPOSED_CASES, OFF_GRID_CASES, TRACKED_CASES, nominal_model, simulated_parameters
from .withheld_verdict import problems, truth_text, verdict_text

DIRECTIONS = {"forward": ("fit", "holdout"), "backward": ("holdout", "fit")}


def case_by_name(name):
    return next(c for c in [*CASES, *OFF_GRID_CASES, *TRACKED_CASES, *COMPOSED_CASES] if c.name == name)


def run(robot, model, folder, doc, name: str, direction: str = "forward", options=None, case=None) -> dict:
    """Diagnose case `name` of a written folder in one direction; `case`: its Case, if not one of
    the module's lists (bench_withheld_random.py)."""
    entry = next(c for c in doc["cases"] if c["name"] == name)
    fit_key, test_key = DIRECTIONS[direction]
    fit, test = (condition(read_recording(folder / entry[k], robot.dof)) for k in (fit_key, test_key))
    p_model = nominal_model(robot)
    case = case or case_by_name(name)
    p_true = simulated_parameters(case, p_model, doc["seed"])
    start = time.perf_counter()
    kwargs = {"options": options} if options is not None else {}
    result = diagnose(robot, model, p_model, [fit], None, test=[test], **kwargs)
    seconds = time.perf_counter() - start
    d = json.loads(to_json(result, {}))
    perfect = perfect_rms(robot, p_true, case.effects, test)
    found = problems(entry["effects"], d, perfect, p_model)
    return {"case": name, "direction": direction, "truth": truth_text(entry["effects"]), "verdict": verdict_text(d),
            "before": d["rms_before"], "after": d["rms_after"], "simple": d["rms_simple"],
            "perfect": perfect.tolist(), "problems": found, "seconds": seconds, "cutoff": [fit.cutoff, test.cutoff],
            "warnings": d["warnings"], "diagnosis": d, "ratio": float(np.max(np.array(d["rms_after"]) / perfect))}
