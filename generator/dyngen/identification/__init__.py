"""Identification of base coefficients by least squares (the paper's eq. 11).

    estimate = identify(model, signals, kind="full")        # or "gravity", "inertia"
    text = identified_yaml(model.manifest, {"full": estimate}, sources)   # what `dyngen extract` reads

Modules: samples (stacked regressors and measurements from recordings), least_squares (the
fit, condition number, standard deviations, unexcited coefficients), output (YAML, table).
"""

from .least_squares import Estimate, fit
from .output import identified_yaml, summary_table
from .samples import identify, stacked

__all__ = ["Estimate", "fit", "identified_yaml", "identify", "stacked", "summary_table"]
