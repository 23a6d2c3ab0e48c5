"""Identification of base coefficients by least squares (the paper's eq. 11).

    estimate = identify(model, signals, kind="full")        # or "gravity", "inertia"
    text = identified_yaml(model.manifest, {"full": estimate}, sources)   # what `dyngen extract` reads

    result = identify_consistent(robot, model, folder, signals)   # physically consistent, with friction

Modules: consistent (weighted least squares over consistent link parameters, friction, offsets and
rotor inertia through the extraction's solver: the order of work), blocks (its recordings a block
at a time, in passes), triangular (least squares accumulated in triangular factors), columns (the terms' columns per
recording: friction, ripple, tilt, terms/), normal (normal equations per part and joint), solver (the consistent
fit of normal equations by the extraction's driver), held_out (lambda and the optional parts on
held-out data), statistics (sandwich standard deviations), options (identify's and the consistent
identification's options), consistent_output (the result, its YAML and tables; the command:
commands/identify_consistent.py); samples (the least-squares fit of
recordings, as identify --ols folds them), least_squares (the fit, condition number, standard deviations,
unexcited coefficients), output (YAML, table).
"""

from .consistent import Consistent, ConsistentOptions, identify_consistent
from .least_squares import Estimate, fit
from .output import identified_yaml, summary_table
from .samples import identify

__all__ = ["Consistent", "ConsistentOptions", "identify_consistent", "Estimate", "fit", "identified_yaml", "identify", "summary_table"]
