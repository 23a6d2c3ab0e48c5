"""A gain, a payload or a scaled gravity (DIFFERS) may be the nominal model's error: where the
re-identified link parameters won joints (reidentify.py), one that gains less than min_gain of
the selection data's mean square beside them, alone on what they leave, is explained by them:
not told apart from the link parameters being off, so not claimed (explained_by_links). And a
run is compared with a control run of the same arm without what is looked for (e.g. unloaded
beside loaded):

    result = compared(result, control, "unloaded.csv")

A gain, a payload or a scaled gravity (DIFFERS: what a load changes) found on the same joints in
the control run's findings is not a sensor or payload finding: it appears with and without what
differs between the runs, so it is the nominal model's error (wrong link parameters, most
often). It is marked suspect with that reason and one warning names all such findings. What the
arm carries in both runs (friction, rotor inertia, offsets, ripple, a tilt) is expected in both
and stays as it is, as does a payload absent from the control run. The control run is diagnosed apart, with the same options
(commands/diagnose.py --control); nothing of it enters the result's figures.
"""

from __future__ import annotations

from dataclasses import replace

from .forward_selection import selection_gain, selection_mse
from .refine import restricted

DIFFERS = ("gain", "payload", "gravity_scale")


def _key(finding) -> tuple:
    return finding.effect, tuple(finding.joints)


def compared(result, control, control_name: str):
    """result with the findings also found in `control` (a Diagnosis) marked suspect and one
    warning naming them, or unchanged when none is."""
    seen = {_key(e) for e in control.selected}
    both, selected = [], []
    for e in result.selected:
        if e.effect in DIFFERS and _key(e) in seen:
            joints = ", ".join(map(str, e.joints))
            both.append(f"{e.effect}" + (f" on joint(s) {joints}" if joints else ""))
            reason = (f"also found in the control run {control_name}: the nominal model's error, not a finding about a "
                      "sensor or a payload")
            e = replace(e, suspect=reason + (f"; {e.suspect}" if e.suspect else ""))
        selected.append(e)
    if not both:
        return result
    line = (f"found also in the control run {control_name}, so the nominal model's error (wrong link parameters, most "
            f"often), not a sensor or payload finding: {'; '.join(both)}")
    return replace(result, selected=selected, warnings=[*result.warnings, line])


def explained_by_links(context, segments, consistent, design, chosen, min_gain) -> list[int]:
    """Indices of the chosen DIFFERS effects that gain less than min_gain on the selection
    samples of the residual the re-identified model leaves (consistent: per segment its correction)."""
    left = [replace(seg, residual=seg.residual - c) for seg, c in zip(segments, consistent)]
    out = []
    for i, c in enumerate(chosen):
        if c.effect.name in DIFFERS:
            alone, (one,) = restricted(context, left, design, [c])
            if selection_gain(one, selection_mse(alone, []), selection_mse(alone, [one])) < min_gain:
                out.append(i)
    return out
