"""Measured data in: CSV recordings (read and checked) and their signal conditioning.

    recordings = [read_recording(path, dof) for path in paths]
    signals = [condition(r, Conditioning(cutoff=1.0, order=4)) for r in recordings]
"""

from .conditioning import Conditioning, Signals, condition
from .recording import Recording, read_recording

__all__ = ["Conditioning", "Recording", "Signals", "condition", "read_recording"]
