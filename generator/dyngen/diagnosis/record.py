"""The diagnosis's result: the findings as types and one record (Diagnosis), built by keyword.
Fields are the diagnosis.json entries (docs/conventions.md); frozen: a step that changes a
finding returns a new one."""

from __future__ import annotations

from dataclasses import dataclass, field, fields


def entry(finding) -> dict:
    """A finding's diagnosis.json entry: its fields in order, an empty optional text left out."""
    return {f.name: getattr(finding, f.name) for f in fields(finding)
            if not (f.default == "" and getattr(finding, f.name) == "")}


@dataclass(frozen=True)
class Finding:
    """One selected effect: what it does on the selection data and the values the fit gave."""
    effect: str  # Term.name
    joints: tuple  # 1-based joints it helps (its own joint for a per-joint effect)
    variant: dict  # settings not fitted (Term.fixed: e.g. a velocity scale)
    values: dict  # parameter -> fitted value, None where the data do not determine it
    std: dict  # parameter -> standard deviation (scaled for the residual's correlation), or None
    units: dict  # parameter -> unit
    derived: dict  # what follows from the values (Term.derived: tilt angles, payload mass, ...)
    selection_gain: float  # relative decrease of the selection data's mean square residual
    rms_before: list  # per joint, selection data, the other selected effects without it
    rms_after: list  # per joint, selection data, with it
    suspect: str = ""  # why it is a symptom rather than a cause ("" if it is not)


@dataclass(frozen=True)
class Unstable:
    """A selected effect not claimed: unstable across stretches of the fit data (stable.py); kept."""
    finding: Finding  # what it would have been claimed as
    per_stretch: list  # per stretch its values (None where the stretch does not determine them)
    reason: str


@dataclass(frozen=True)
class Refusal:
    """A selected effect refused once fitted with the others: values not physically possible."""
    candidate: str  # Candidate.key, or what of it was refused
    values: list
    reason: str = ""  # "" when its values alone are impossible


@dataclass(frozen=True)
class CandidateGain:
    """A candidate tried alone: its selection gain."""
    candidate: str
    selection_gain: float


@dataclass(frozen=True)
class RecordingNote:
    """What conditioning did to one recording, and the role it played."""
    recording: str
    role: str  # "fit", "select" or "test"
    note: str
    trimmed_samples: int


@dataclass(frozen=True)
class LinksOff:
    """"Link parameters off": joints where re-identified consistent link parameters beat every effect."""
    joints: list  # 1-based
    regularisation: float  # toward the given parameters, chosen on selection data
    selection: list  # per regularisation tried: {"regularisation", "selection_weighted_ms"}
    link_parameters: list  # per link, the standard parameters
    friction: dict
    smoothing: list
    lambda_min: list
    at_bounds: list
    dropped_columns: list
    fit_rms: list


@dataclass(frozen=True)
class Diagnosis:
    robot: str
    joints: int
    split: str  # how selection data were obtained
    judged_on: str  # "test" (recordings used for nothing else) or "selection" (no test data given)
    selected: list[Finding]
    rms_before: list  # per joint, on the judged data, nominal model
    rms_after: list  # per joint, on the judged data, with the final model (effects; simple model where it won)
    rms_effects: list  # per joint, on the judged data, with the selected effects alone
    rms_simple: list  # per joint, on the judged data, the simple model (terms/simple_model.py)
    selection_before: list  # per joint, selection data
    selection_after: list
    selection_simple: list
    simple_wins: list  # 1-based joints where the simple model beat the effects on selection data
    simple_values: list  # per joint b, Fc, Fv
    peak_before: list
    noise_rms: list  # per joint estimate of the white part of the final judged residual
    where: list  # per joint: phases of the nominal judged residual (phases.by_phase), with rms_after
    candidates: list[CandidateGain]  # every candidate, the best alone first
    steps: list
    dropped: list  # selected forward, then dropped as not significant (correlated residual)
    refused: list[Refusal]  # selected, then refused: implausible values once fitted with the others
    superseded: list[Finding]  # per-joint effects on joints another model won; effects not told apart from wrong links (suspect)
    unstable: list[Unstable]  # selected, kept in the model, but not claimed: unstable across blocks
    correlation_samples: float  # integrated autocorrelation time used to scale the deviations
    warnings: list = field(default_factory=list)
    joint_models: list = field(default_factory=list)  # per joint "effects", "simple", "effects + simple"... (joints.py)
    completed: dict = field(default_factory=dict)  # joint -> values of [its effects' columns, b, Fc, Fv]
    conditioning: list[RecordingNote] = field(default_factory=list)
    segments: list = field(default_factory=list)  # roles.Segment, for figures
    within_fit_speeds: dict = field(default_factory=dict)  # share of judged samples beyond the fit speeds; RMS within
    consistent: LinksOff | None = None  # "link parameters off", where the consistent model won
    reidentified: object = None  # its identification.consistent.Consistent (for the written parameters)
    control: str = ""  # what the comparison with a control run (--control) found, "" without one
