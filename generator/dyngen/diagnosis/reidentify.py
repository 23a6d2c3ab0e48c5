"""The link parameters re-identified, physically consistent, as a per-joint alternative model.

A diagnosis explains the residual with named effects; when the link parameters themselves are
off (masses, centres of mass, inertias), no effect of the library covers it, and the
unconstrained "errors in every base coefficient" over-fits. Here the consistent identification
with friction (identification/consistent.py: every link's pseudo-inertia positive definite,
friction that opposes motion, a tilted base, regularised toward the diagnosed parameters) is
the alternative, with the three roles of data kept:

  excited by default (Options.reidentify None) all of this runs only where the fit samples
          determine the link parameters well enough for what the effects leave: a residual
          the re-identification cannot express (RMS s_j on joint j) can, aligned with the
          weakest direction of the rigid body's base columns (each scaled to unit norm, at
          GATE_RATE), move their torque on a trajectory that excites every direction alike
          by up to kappa s_j (kappa: the columns' condition number), and the most it can gain
          on joint j is the nominal residual r_j: it runs where kappa <= max_j r_j / s_j. The
          real LWR4+ (kappa 53-78, ratios 14-21) stays as it was (the re-identification,
          forced there, took joint 2 of m3 from 0.446 to 0.633 Nm from positions alone, where
          the effects predict); the simulated Fourier excitations and Table V (kappa 10-28,
          ratios 53-670 where an effect or wrong links are in the data) run it; a residual at
          the noise (ratio 1) does not;
  gate    cheap: the residual the selected effects leave on the fit samples, regressed on the
          rigid body's base columns (unconstrained, at GATE_RATE); the joints where that gains
          `min_gain` of the mean square on the selection samples are those whose residual the
          link parameters explain; none, and nothing more is done (a residual that is noise, as
          with every effect found, never gains; a tilt the effects left is not the links');
  fit     consistent identification on the fit samples, decimated to about RATE Hz, with the
          regularisation toward the diagnosed parameters chosen from GRID on the selection
          samples (one restart: the problem is convex);
  select  per joint, on the gate's joints only, the consistent model wins where it beats the
          best other model on the selection samples as a model with JOINT_VALUES values must
          (joints.py): a joint at the noise is not taken by six friction columns fitting it;
  refit   on every fit sample (the selection blocks included, as the effects are) with the
          chosen regularisation, kept only if its residual on its fit data is nowhere more than
          REFIT_WORSE times the first one's. (On the withheld "coefficients" case at 500 Hz, the
          refit's barrier solve pinned m2 at its bound and left 0.19 Nm on joint 2 where the fit
          on the fit blocks alone left 0.02, with the same regularisation; not understood yet.)

Test data are never seen here.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .record import LinksOff

RATE = 200.0  # Hz: samples used by the re-identification (the motion's band is far below)
GATE_RATE = 50.0  # Hz: samples used by the gate (a rough test; 0.1 s for 30 s of data)
# regularisation toward the diagnosed parameters, chosen on selection data; 0 included: the
# consistent optimum at 0.3 sits near the diagnosed links when they are 10 % off (the withheld
# "coefficients" case), and only a barrier run that stopped short (as with one BLAS thread
# before) left it near the data
GRID = (0.0, 0.1, 0.3, 3.0)
REFIT_WORSE = 1.25  # the refit must fit its (larger) data about as well as the first fit did
RESTARTS = 2  # of the final solve (the held-out choice of the regularisation uses one)
FRICTION = ("coulomb", "viscous", "offset", "armature", "ripple")
JOINT_VALUES = 7  # per joint: Fc, Fv, offset, Ia, two ripple values, and one for the shared link parameters


def pieces(segments, role: str) -> list:
    """Conditioned signals of every contiguous run of `role` samples, decimated to ~RATE Hz."""
    out = []
    for seg in segments:
        sig, mask = seg.signals, getattr(seg, role)
        idx = np.flatnonzero(mask)
        if not idx.size:
            continue
        step = max(1, int(round(sig.rate / RATE)))
        breaks = np.flatnonzero(np.diff(idx) > 1)
        for a, b in zip(np.r_[0, breaks + 1], np.r_[breaks, idx.size - 1]):
            k = np.arange(idx[a], idx[b] + 1, step)
            if k.size < 20:
                continue
            out.append(dataclasses.replace(sig, t=sig.t[k], q=sig.q[k], qd=sig.qd[k], qdd=sig.qdd[k], tau=sig.tau[k],
                                           trim=0, extra={}))
    return out


def _gate_columns(model, seg, k):
    sig = seg.signals
    return model.batch("regressor", sig.q[k], sig.qd[k], sig.qdd[k])


def excitation(model, segments) -> tuple[float, float]:
    """(kappa, bound): the condition number of the rigid body's base columns on the fit samples
    (at GATE_RATE, each column scaled to unit norm), and the largest ratio over joints of the
    nominal residual's RMS to that of what the effects leave (Segment.correction) there."""
    G, nominal, left = None, 0.0, 0.0
    for seg in segments:
        k = np.flatnonzero(seg.fit)[::max(1, int(round(seg.signals.rate / GATE_RATE)))]
        if k.size:
            A = _gate_columns(model, seg, k)
            A = A.reshape(-1, A.shape[2])
            G = A.T @ A if G is None else G + A.T @ A
            nominal = nominal + np.sum(seg.residual[seg.fit] ** 2, axis=0)
            left = left + np.sum((seg.residual - seg.correction)[seg.fit] ** 2, axis=0)
    if G is None:
        return float("inf"), 0.0
    scale = np.sqrt(np.maximum(np.diag(G), 1e-300))
    ev = np.linalg.eigvalsh(G / np.outer(scale, scale))
    bound = float(np.max(np.sqrt(nominal / np.maximum(left, 1e-300 * np.max(nominal)))))
    return float(np.sqrt(ev[-1] / max(ev[0], 1e-300 * ev[-1]))), bound


def gate(model, segments, remaining, min_gain: float) -> list[int]:
    """Joints (0-based) on whose selection samples the unconstrained fit of the rigid body's
    base columns to `remaining` (per segment, the residual left by the per-joint
    models) gains at least `min_gain` of the mean square."""
    G = g = None
    sel = []
    for seg, rest in zip(segments, remaining):
        step = max(1, int(round(seg.signals.rate / GATE_RATE)))
        for role in ("fit", "select"):
            k = np.flatnonzero(getattr(seg, role))[::step]
            if not k.size:
                continue
            A, r = _gate_columns(model, seg, k), rest[k]
            if role == "fit":
                A2 = A.reshape(-1, A.shape[2])
                G = A2.T @ A2 if G is None else G + A2.T @ A2
                g = A2.T @ r.reshape(-1) if g is None else g + A2.T @ r.reshape(-1)
            else:
                sel.append((A, r))
    if G is None or not sel:
        return []
    scale = np.sqrt(np.maximum(np.diag(G), 1e-300))
    ev, V = np.linalg.eigh(G / np.outer(scale, scale))
    keep = ev > 1e-10 * ev[-1]
    x = (V[:, keep] @ ((V[:, keep].T @ (g / scale)) / ev[keep])) / scale
    before = sum(np.sum(r ** 2, axis=0) for _, r in sel)
    after = sum(np.sum((r - A @ x) ** 2, axis=0) for A, r in sel)
    return [j for j in range(before.size) if after[j] < (1 - min_gain) * before[j]]


def identify(robot, model, p, fit_pieces, select_pieces=None, regularisation=None):
    """The consistent identification (regularised toward p) on decimated pieces."""
    from ..identification.consistent import ConsistentOptions, identify_consistent

    options = ConsistentOptions(friction=FRICTION, prior=np.asarray(p, dtype=float), tilt=True, restarts=RESTARTS,
                                grid=GRID, regularisation=regularisation)
    return identify_consistent(robot, model, model.folder, fit_pieces, options, select=select_pieces)


def corrections(result, model, segments) -> list:
    """Per segment (T, N): the consistent model's torque less the diagnosed model's."""
    return [result.predict(model, seg.signals) - seg.tau_model for seg in segments]


def finding(robot, result, joints: list) -> LinksOff:
    """The finding: joints where the consistent parameters won, and the parameters."""
    from ..parameters import PER_LINK

    links = np.asarray(result.p).reshape(-1, PER_LINK)
    f = {k: [None if not np.isfinite(x) else float(x) for x in np.atleast_1d(v)] for k, v in result.friction.items()}
    return LinksOff(
        joints=[j + 1 for j in joints], regularisation=result.regularisation,
        selection=[{"regularisation": a, "selection_weighted_ms": b} for a, b in result.selection],
        link_parameters=[row.tolist() for row in links], friction=f, smoothing=result.smoothing.tolist(),
        lambda_min=result.lambda_min.tolist(), at_bounds=list(result.at_bounds),
        dropped_columns=list(result.dropped_columns), fit_rms=result.residual_rms.tolist())
