"""Least squares over recordings of any length and number: each recording read in blocks and
folded into per-joint triangular factors (identification/triangular.py) by a per-recording step (step.py) that
runs in worker processes or on a Dask cluster (engine.py); the pooled fit and the per-recording
comparison (pooled.py). Memory depends on the number of coefficients, not on the rows.
"""
