"""Diagnosis of the sim-to-real gap: where the residual tau_measured - tau_model lies, which
unmodelled effect explains it (chosen on held-out data), and how far it shrinks.

    result = diagnose(robot, model, p, fit_signals, select_signals, options, test=test_signals)
    write_outputs(result, robot, p, out_dir, sources, sign_velocity)   # diagnosis_files.py

The stages, in order (pipeline.py runs them):

    0. roles.py      recordings cut into fit, selection and test samples; the nominal residual
    1. fit.py        the moments of every candidate (moments.py) from the library of effects
                     (dyngen.terms.library: each a torque term with the diagnosis's rules on it)
    2. forward_selection.py  forward selection on the selection data
    3. settle.py     nonlinear settings refined (refine.py), insignificant effects pruned,
                     implausible ones refused
    4. choose.py     per joint: effects, the simple model (terms/simple_model.py), both, or re-identified
                     link parameters (joints.py, reidentify.py)
    5. judge.py      the figures on the judged data, per phase of the motion (phases.py)
    6. findings.py   the findings, notes.py the warnings, record.py the result (Diagnosis);
                     report_text.py, residual_figures.py and updated_model.py write them
                     (diagnosis_files.py)
"""

from .diagnose_options import Options
from .pipeline import diagnose
from .record import Diagnosis

__all__ = ["Diagnosis", "Options", "diagnose"]
