"""Measured data in: CSV recordings (read and checked) and their signal conditioning.

    recordings = [read_recording(path, dof) for path in paths]
    signals = [condition(r) for r in recordings]   # cutoff decided from the data (Conditioning)
"""

from .conditioning import Conditioning, Signals, condition
from .reader import read_recording
from .recording import Recording

__all__ = ["Conditioning", "Recording", "Signals", "condition", "read_recording"]
