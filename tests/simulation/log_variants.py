"""Written case folders (withheld_cases.write_cases) as loggers would have written them, and the
judgement of a diagnosis on them.

    out = variant(folder, "polled", out)          # every CSV through logger.py, the rest copied
    ok = below_the_torques(before, test_signals)  # the nominal residual at most the torque

PATHOLOGIES name logger.py's transformations with the shares the issue measured on real logs
(franka_ros: 5.5 % repeated rows; steps of 0.7-8.8 ms at 1 kHz): repeated rows, a polling
logger on its own jittered clock (repeated, dropped and late rows at once), 5 % dropped samples,
stamps late by up to 0.4 ms, torques updated at a tenth of the rate, a bus's errors (one wrong
position or torque in a thousand rows, an angle logged in [0, 2 pi)). Each file's seed is its
name's length, so a variant folder is the same every time.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from . import logger

PATHOLOGIES = {
    "repeated": lambda text, seed: logger.repeated(text, 0.055, seed),
    "polled": lambda text, seed: logger.polled(text, seed),
    "dropped": lambda text, seed: logger.dropped(text, 0.05, seed),
    "jittered": lambda text, seed: logger.jittered(text, 0.4e-3, seed),
    "held": lambda text, seed: logger.held(text, "tau", 10),
    "glitched": lambda text, seed: logger.glitched(text, seed),
}

TORQUE_SHARE = 0.05  # joints carrying less torque RMS than this share of the largest are not judged
ABOVE = 1.02  # rounding of the reported RMS


def variant(folder, name: str, out) -> Path:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for f in Path(folder).iterdir():
        if f.suffix == ".csv":
            (out / f.name).write_text(PATHOLOGIES[name](f.read_text(), len(f.name)))
        else:
            shutil.copy(f, out / f.name)
    return out


def below_the_torques(before, sig) -> bool:
    """The nominal test residual (RMS per joint, `before`) at most the measured torque (RMS) of
    the conditioned test signals on every joint carrying torque (TORQUE_SHARE of the largest;
    the LWR's joint 7 carries 0.01 Nm); a joint whose torque is all friction, which the nominal
    model lacks, has a residual as large as its torque."""
    torque = np.sqrt(np.mean(sig.tau[sig.inner()] ** 2, axis=0))
    judged = torque > TORQUE_SHARE * torque.max()
    return bool(np.all(np.asarray(before)[judged] <= ABOVE * torque[judged]))
