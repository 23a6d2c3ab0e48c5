"""Whether a recording's conditioning can be trusted before anything is claimed from it (`dyngen
diagnose`, `dyngen identify`): where the nominal residual exceeds ABOVE times the torque, the
recording is conditioned again (automatic cutoff only); when nothing helps, Unusable
(docs/measured-data.md, "When conditioning cannot be trusted").

    signals = checked(model, s, signals, "diagnosis")        # or "identification"
    signals = checked(model, s, signals, "identification", as_recorded=[(name, windows)])"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..catalogue import RNEA
from ..errors import InputError
from .conditioning import AUTO, condition

TORQUE_FLOOR = 0.05  # joints carrying less torque RMS than this share of the largest are not judged
ABOVE = 1.5  # a residual this many times the torque's RMS is not the model's error (a joint whose torque is
# all friction, which the nominal model lacks, has a residual as large as its torque)
SCALE_RANGE = (1 / 3, 3.0)  # measured / model torque: beyond it no sensor gain but a convention (sign, unit, gear)
SCALE_EXPLAINS = 0.3  # ... when the model scaled by it leaves at most this share of the measured torque's RMS
# (91 % of its power explained: torques reversed in time gave -0.61 on the LWR's joint 4, leaving 0.79)
READING_CUTS, READING_SHARE = 0.1, 0.5  # a reading of the log in other conventions must cut the residual share so
FIT_EXPLAINS = 0.25  # a rigid-body fit leaving at most this share of a joint's torque RMS explains it (94 % of its
# power; torques reversed in time left 0.49 on the LWR's joint 4: 64 coefficients fit part of anything)
MODEL_FLOOR = 1e-3  # joints whose model torque is below this share of the largest are not judged for a convention
UNIT_ABOVE = 3.0  # a joint's measured torque this many times the arm's largest model torque is in other units
ARM_UNIT = (0.1, 10.0)  # the whole arm's measured / model torque: beyond, a unit (no nominal model is this far off)
KEEP = 1.1  # the highest cutoff whose mean squared residual share is within this factor of the best
MIN_CUTOFF = 0.5  # Hz
EXIT_UNUSABLE = 3  # `dyngen diagnose` and `identify` exit status when a recording's conditioning cannot be trusted
# what cannot be done, and what is therefore not claimed, in Unusable's line
PURPOSES = {"diagnosis": ("a diagnosis", "no effect is claimed"),
            "identification": ("an identification", "nothing is identified")}


@dataclass
class Trial:
    how: str  # what was tried, in words
    cutoff: float | None
    torque: np.ndarray  # per joint RMS of the measured torque (inner samples)
    residual: np.ndarray  # per joint RMS of the nominal residual
    model: np.ndarray | None = None  # per joint RMS of the nominal model's torque
    scale: np.ndarray | None = None  # per joint least-squares factor of the model's torque in the measured one
    scaled: np.ndarray | None = None  # per joint RMS of measured - scale x model

    @property
    def judged(self) -> np.ndarray:
        return self.torque > TORQUE_FLOOR * float(self.torque.max())

    @property
    def above(self) -> list[int]:
        """0-based joints whose nominal residual exceeds their torque."""
        return [int(j) for j in np.flatnonzero(self.judged & (self.residual > ABOVE * self.torque))]

    @property
    def conventions(self) -> list[tuple[int, float]]:
        """(0-based joint, factor) where the measured torque is the model's times a factor that sets the joint
        apart from the rest of the arm by more than SCALE_RANGE (a sign, a unit, a gear ratio: link
        parameters off by a common factor are not a convention), that factor explaining most of the
        measured torque; or every such joint, where the arm's common factor is beyond ARM_UNIT (torques
        logged in mNm). Judged on joints whose model torque is above TORQUE_FLOOR of the largest: where
        it is smaller, a payload alone can multiply it (a wrist's by 18, the `payload_tilt` case); there
        only a torque beyond UNIT_ABOVE times the arm's largest model torque is a unit."""
        if self.scale is None or not self.model.max() > 0:
            return []
        largest = float(self.model.max())
        explained = self.scaled <= SCALE_EXPLAINS * self.torque
        loaded = explained & (self.model > TORQUE_FLOOR * largest)
        judged = explained & (self.model > MODEL_FLOOR * largest) & (loaded | (self.torque > UNIT_ABOVE * largest))
        common = float(np.median(self.scale[loaded])) if loaded.any() else 1.0
        lo, hi = SCALE_RANGE
        if not ARM_UNIT[0] <= common <= ARM_UNIT[1]:
            return [(int(j), float(self.scale[j])) for j in np.flatnonzero(judged)]
        return [(int(j), float(self.scale[j])) for j in np.flatnonzero(judged) if not lo <= self.scale[j] / common <= hi]

    @property
    def share(self) -> float:
        """Mean over judged joints of (residual / torque)^2."""
        j = self.judged
        return float(np.mean((self.residual[j] / self.torque[j]) ** 2)) if j.any() else 0.0


@dataclass
class Untrusted:
    recording: str
    trials: list = field(default_factory=list)  # the first is the automatic conditioning
    named: str | None = None  # the convention found to differ from the model's (a sign, a unit), in words
    as_recorded: bool = False  # read in blocks: its columns as recorded, not conditioned again


class Unusable(Exception):

    def __init__(self, line: str, recordings: list):
        super().__init__(line)
        self.line = line
        self.recordings = recordings  # Untrusted per recording that failed


def trial(model, s, sig, how: str) -> Trial:
    return pooled(model, s, [sig], how)


def pooled(model, s, pieces, how: str) -> Trial:
    """The Trial over the inner samples of every piece at once (the windows of one recording)."""
    tau = np.concatenate([sig.tau[sig.inner()] for sig in pieces])
    model_tau = np.concatenate([model.batch(RNEA.name, sig.q[keep], sig.qd[keep], sig.qdd[keep], s)
                                for sig in pieces for keep in [sig.inner()]])
    scale = np.sum(tau * model_tau, axis=0) / np.maximum(np.sum(model_tau ** 2, axis=0), 1e-300)
    return Trial(how, pieces[0].cutoff, np.sqrt(np.mean(tau ** 2, axis=0)),
                 np.sqrt(np.mean((tau - model_tau) ** 2, axis=0)), np.sqrt(np.mean(model_tau ** 2, axis=0)),
                 scale, np.sqrt(np.mean((tau - scale * model_tau) ** 2, axis=0)))


def _again(sig, **changes):
    return condition(sig.source, dataclasses.replace(sig.options, **changes))


def _alternatives(sig):
    """(how, signals) conditioned otherwise, highest cutoff first."""
    first = sig
    if sig.cutoff is None or not sig.note.startswith("qd, qdd differentiated"):
        try:
            first = _again(sig, differentiate=True, cutoff=AUTO)
        except (ValueError, InputError):  # InputError: a gap leaves too few samples (conditioning.MIN_DATA)
            return
        yield "positions differentiated, automatic cutoff", first
    start = first.cutoff if first.cutoff is not None else first.rate / 20
    cutoff = start / 2
    while cutoff >= MIN_CUTOFF and sig.t.size > 8 * first.rate / cutoff:
        try:
            yield f"positions differentiated, {cutoff:.3g} Hz", _again(sig, differentiate=True, cutoff=cutoff)
        except (ValueError, InputError):
            return
        cutoff /= 2


def _joints(js) -> str:
    return ", ".join(str(j + 1) for j in js)


def checked(model, s, signals: list, purpose: str = "diagnosis", as_recorded=()) -> list:
    """signals with any untrustworthy recording conditioned again; raises Unusable (see _checked).
    Where the nominal residual is above the torque but a rigid-body fit of the data explains every such
    joint (data/rigid_fit.py), the conditioning is sound and the link parameters are off: an
    identification goes on with a warning (fixing them is its purpose), a diagnosis stops, its line
    saying so."""
    out, off, firsts = [], [], {}
    for sig in signals:
        if sig.tau is not None and sig.t.size >= 16:
            firsts[id(sig)] = first = trial(model, s, sig, f"as conditioned ({sig.note})")
            if first.above and not first.conventions and _explained(model, sig, first):
                off.append((sig, first))
                continue
        out.append(sig)
    if off and purpose != "identification":
        sig, first = off[0]
        raise Unusable(f"the data cannot support {PURPOSES[purpose][0]}: on {sig.name} the nominal link parameters are "
                       f"far off ({_rms_pair(first)}), while a rigid-body fit of the data explains them: identify the "
                       f"link parameters first (dyngen identify); {PURPOSES[purpose][1]}", [Untrusted(sig.name, [first])])
    done = iter(_checked(model, s, out, firsts, purpose, as_recorded))
    for sig, first in off:
        sig.warnings.append(f"{sig.name}: the nominal link parameters leave a residual above the measured torque "
                            f"({_rms_pair(first)}), while a rigid-body fit of the data explains it: the conditioning "
                            "is sound, the link parameters are off")
    offs = {id(sig) for sig, _ in off}
    return [sig if id(sig) in offs else next(done) for sig in signals]


def _explained(model, sig, first: Trial) -> bool:
    from .rigid_fit import rigid_fit_residual

    left = rigid_fit_residual(model, sig)
    return all(left[j] <= FIT_EXPLAINS * first.torque[j] for j in first.above)


def _checked(model, s, signals: list, firsts: dict, purpose: str = "diagnosis", as_recorded=()) -> list:
    """signals with any untrustworthy recording conditioned again; raises Unusable (its line says
    that the data cannot support the `purpose`, a key of PURPOSES). firsts: id(signals) -> its Trial
    as conditioned (those without one are not judged). as_recorded: (name, pieces)
    of recordings that cannot be conditioned again (read in blocks, their columns as recorded),
    each judged over its conditioned pieces pooled."""
    out, failed = [], []
    for sig in signals:
        first = firsts.get(id(sig))
        if first is None:
            out.append(sig)
            continue
        named = _other_convention(model, s, sig, first) if first.above else None  # degrees, no gravity
        if named is None and first.conventions:
            named = _conventions(first.conventions)  # a sign, a unit, a gear
        if named is not None:  # no conditioning changes a sign or a unit
            failed.append(Untrusted(sig.name, [first], named=named))
            out.append(sig)
            continue
        if not first.above:
            out.append(sig)
            continue
        record = Untrusted(sig.name, [first])
        best = None
        if sig.source is not None and sig.options is not None and sig.options.cutoff == AUTO:
            tried = [(trial(model, s, other, how), other) for how, other in _alternatives(sig)]
            record.trials += [t for t, _ in tried]
            good = [(t, o) for t, o in tried if not t.above]
            if good:
                floor = min(t.share for t, _ in good)
                best = next((t, o) for t, o in good if t.share <= KEEP * floor)  # highest cutoff first
        if best is None:
            failed.append(record)
            out.append(sig)
            continue
        t, other = best
        other.warnings.append(
            f"{sig.name}: the automatic conditioning left a nominal residual above the measured torque on joint(s) "
            f"{_joints(first.above)} ({_rms_pair(first)}); conditioned again: {t.how} (residual {_rms_pair(t)})")
        other.note = f"conditioned again after the automatic choice failed: {other.note}"
        out.append(other)
    for name, pieces in as_recorded:
        pieces = [sig for sig in pieces if sig.tau is not None and sig.t.size >= 16]
        first = pooled(model, s, pieces, f"as recorded, read in blocks ({pieces[0].note})") if pieces else None
        if first is not None and (first.above or first.conventions):
            failed.append(Untrusted(name, [first], as_recorded=True,
                                    named=_conventions(first.conventions) if first.conventions else None))
    if failed:
        worst = failed[0].trials[0]
        what, claim = PURPOSES[purpose]
        convention = next((r for r in failed if r.named), None)
        if convention is not None:
            raise Unusable(f"the data cannot support {what}: on {convention.recording} {convention.named}; {claim}",
                           failed)
        line = (f"the data cannot support {what}: on {', '.join(r.recording for r in failed)} the nominal "
                f"model's residual exceeds the measured torque on joint(s) {_joints(worst.above)} ({_rms_pair(worst)}) "
                + ("with its columns as recorded, read in blocks and not conditioned again"
                   if all(r.as_recorded for r in failed) else "with every conditioning tried")
                + " (a log whose rows or stamps cannot be repaired, torques that do not "
                f"belong to the positions, or parameters far off); {claim}")
        raise Unusable(line, failed)
    return out


def checked_roles(model, s, fit, select, test):
    """checked() over the fit, select and test recordings of a diagnosis at once (None stays None)."""
    groups = [list(g) if g else [] for g in (fit, select, test)]
    done = checked(model, s, [x for g in groups for x in g], "diagnosis")
    out, k = [], 0
    for original, g in zip((fit, select, test), groups):
        out.append(done[k:k + len(g)] if original is not None else None)
        k += len(g)
    return tuple(out)


def _other_convention(model, s, sig, first: Trial) -> str | None:
    """Where the nominal residual is above the torque: positions in degrees, or torques without gravity
    (a gravity-compensated command, an external-torque estimate), when that reading leaves no judged
    joint above its torque and cuts the mean squared residual share to READING_CUTS of what it was
    and below READING_SHARE (torques reversed in time, read without gravity, keep a share near 1)."""
    keep = sig.inner()
    q, qd, qdd, tau = sig.q[keep], sig.qd[keep], sig.qdd[keep], sig.tau[keep]
    rad = np.pi / 180
    zero = np.zeros_like(q)
    readings = (
        ("its positions are in degrees: read in radians, the nominal model leaves {}; convert them to radians",
         lambda: model.batch(RNEA.name, q * rad, qd * rad, qdd * rad, s)),
        ("its torques leave gravity out (a gravity-compensated command or an external-torque estimate): the "
         "nominal model without gravity leaves {}; log the measured joint torques",
         lambda: model.batch(RNEA.name, q, qd, qdd, s) - model.batch(RNEA.name, q, zero, zero, s)))
    for words, predicted in readings:
        read = Trial(words, first.cutoff, first.torque, np.sqrt(np.mean((tau - predicted()) ** 2, axis=0)))
        if not read.above and read.share <= min(READING_CUTS * first.share, READING_SHARE):
            pairs = ", ".join(f"J{j + 1} {read.residual[j]:.3g} vs {first.torque[j]:.3g} Nm" for j in first.above[:4])
            return words.format(f"{pairs} (as logged: {_rms_pair(first)})")
    return None


def _conventions(found) -> str:
    """In words: joints whose measured torque is the model's times a factor no sensor gain has."""
    parts = []
    for j, k in found:
        why = ("its sign differs from the model's: the joint's positive direction or the torque's sign" if k < 0 else
               "a unit or a gear, not a sensor gain: Nm logged as mNm gives 1000, a motor-side torque the gear "
               "ratio's inverse, a current the torque constant's inverse")
        parts.append(f"joint {j + 1}'s measured torque is {k:.3g} x the nominal model's ({why})")
    return "; ".join(parts)


def _rms_pair(t: Trial) -> str:
    js = t.above or [int(np.argmax(np.where(t.judged, t.residual / np.maximum(t.torque, 1e-300), 0)))]
    return ", ".join(f"J{j + 1} {t.residual[j]:.3g} vs {t.torque[j]:.3g} Nm" for j in js[:4])
