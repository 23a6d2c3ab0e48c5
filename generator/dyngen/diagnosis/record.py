"""The diagnosis's result: one record, built by keyword at the end of the pipeline (pipeline.py)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Diagnosis:
    robot: str
    joints: int
    split: str  # how selection data were obtained
    judged_on: str  # "test" (recordings used for nothing else) or "selection" (no test data given)
    selected: list  # per chosen candidate: dict (see docs/conventions.md, diagnosis JSON)
    rms_before: list  # per joint, on the judged data, nominal model
    rms_after: list  # per joint, on the judged data, with the final model (effects; simple model where it won)
    rms_effects: list  # per joint, on the judged data, with the selected effects alone
    rms_simple: list  # per joint, on the judged data, the simple model (terms/simple_model.py)
    selection_before: list  # per joint, selection data
    selection_after: list
    selection_simple: list
    simple_wins: list  # 1-based joints where the simple model beat the effects on selection data
    # (joint_models below: per joint "effects", "simple" or "effects + simple", joints.py)
    simple_values: list  # per joint b, Fc, Fv
    peak_before: list
    noise_rms: list  # per joint estimate of the white part of the final judged residual
    where: list  # per joint: phases of the nominal judged residual (phases.by_phase), with rms_after
    candidates: list  # every candidate: its selection gain when tried alone
    steps: list
    dropped: list  # selected forward, then dropped as not significant (correlated residual)
    refused: list  # selected, then refused: implausible values once fitted with the others
    superseded: list  # per-joint effects on joints the simple model won
    correlation_samples: float  # integrated autocorrelation time used to scale the deviations
    warnings: list = field(default_factory=list)
    joint_models: list = field(default_factory=list)
    completed: dict = field(default_factory=dict)  # joint -> values of [its effects' columns, b, Fc, Fv]
    conditioning: list = field(default_factory=list)  # per recording: what was done to it
    segments: list = field(default_factory=list)  # roles.Segment, for figures
    # per joint on the judged data at the joint velocities the fit data covered: share of samples
    # beyond them, RMS of the final and of the simple model there (velocity laws extrapolate beyond)
    within_fit_speeds: dict = field(default_factory=dict)
    consistent: dict | None = None  # "link parameters off": reidentify.finding, where the consistent model won
    reidentified: object = None  # its identification.consistent.Consistent (for the written parameters)
