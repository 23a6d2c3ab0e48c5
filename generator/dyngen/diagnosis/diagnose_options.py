"""The diagnosis's options: `dyngen diagnose`'s flags, and without option(...) the method's settings."""

from __future__ import annotations

from dataclasses import dataclass

from ..options import option
from ..terms import DEFAULT_NAMES, NAMES
from ..terms.friction import SIGN_SCALE
from .forward_selection import ALPHA, MIN_GAIN


@dataclass(frozen=True)
class Options:
    effects: tuple | None = option(
        None, f"comma-separated effects to try (default: {', '.join(DEFAULT_NAMES)}; also: "
        f"{', '.join(n for n in NAMES if n not in DEFAULT_NAMES)})", metavar="LIST", listed=True)
    min_gain: float = option(MIN_GAIN, "least selection gain to select an effect, as a share of a joint's mean "
                             "square", metavar="G", bounds=(0.0, 1.0))
    alpha: float = ALPHA  # significance level of the selection and the pruning (forward_selection.py)
    sign_velocity: float = option(SIGN_SCALE, "sign(qd) of the Stribeck and direction terms is smoothed as tanh(qd / V), "
                                  "V in rad/s (Coulomb's own scale is fitted)", metavar="V", bounds=(0.0, 1e3),
                                  above=True)
    block_seconds: float = 2.0  # without selection recordings: blocks of this length, each third selects in turn
    reidentify: bool | None = option(
        None, "always re-identify physically consistent link parameters (with friction and a tilted base) from the fit "
        "data, and use them on the joints where they beat every effect and the simple model on selection data; says "
        "'link parameters off' and writes them to consistent/. By default this is done where the fit data excite the "
        "link parameters well enough for what the effects leave (diagnosis/reidentify.py); --no-reidentify never", const=True)
