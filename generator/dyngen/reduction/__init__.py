"""Reduction: from the 10N standard parameters to a minimal set of base coefficients."""
