"""Identification of base coefficients by least squares (the paper's eq. 11), and the
physically consistent identification with friction (consistent.py: its order of work).

    estimate = identify(model, signals, kind="full")        # or "gravity", "inertia"
    text = identified_yaml(model.manifest, {"full": estimate}, sources)   # what `dyngen extract` reads

    result = identify_consistent(robot, model, folder, signals)   # physically consistent, with friction
"""

from .consistent import Consistent, ConsistentOptions, identify_consistent
from .least_squares import Estimate
from .samples import identified_yaml, identify, summary_table

__all__ = ["Consistent", "ConsistentOptions", "identify_consistent", "Estimate", "identified_yaml", "identify", "summary_table"]
