"""Diagnosis of the sim-to-real gap: where the residual tau_measured - tau_model lies, which
unmodelled effect explains it (chosen on held-out data), and how far it shrinks.

    result = diagnose(robot, model, p, fit_signals, holdout_signals)
    write_outputs(result, robot, out_dir)   # report.md, diagnosis.json, figures, updated model

Modules: effects/ (the library of candidate effects), design (moments of every candidate),
selection (forward selection on held-out data), phases (where), run (the whole diagnosis),
report (markdown, JSON), figures (PNG), model (the updated model).
"""

from .run import Diagnosis, Options, diagnose

__all__ = ["Diagnosis", "Options", "diagnose"]
