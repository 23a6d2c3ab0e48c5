"""Does a diagnosis (diagnosis.json, docs/conventions.md) match the truth of a withheld case
(truth.json, tests/simulation/withheld_cases.py)? `problems(truth, diagnosis, noise)` lists every
mismatch as a sentence; an empty list is a pass.

The verdict must name exactly the injected effects on exactly their joints, recover each
magnitude within 20 %, and leave a held-out RMS within 1.5 noise sigmas on every joint.

The truth and the diagnosis name some effects differently; the translation:

  stribeck   truth fc, fs, vs: the law sign(qd) (fc + (fs - fc) exp(-(qd/vs)^2)). The diagnosis
             expresses it as Coulomb Fc on the joint plus Stribeck Fs (the excess) at variant vs:
             fc = Fc, fs = Fc + Fs.
  payload    truth: 10 dynamic parameters of a body on link N (joints [N]). The diagnosis: 10
             standard parameters of the last link (always link N here). Compared: the mass and
             the first moments m c, the parts the trajectories determine well (the inertia about
             the origin is mostly absorbed by the link's own coefficients).
  tilt       truth: the tilted base-frame gravity vector. The diagnosis: dg1, dg2, dgn along
             u1, u2, n, where n = gravity / |gravity|, u1 = the base axis least aligned with n
             made perpendicular to it, u2 = n x u1 (terms/tilt.py). Compared: the change of the
             gravity vector, within 20 % of its norm.
  coefficients  truth: the simulated links p_true. The diagnosis: errors of the base
             coefficients, named by their expressions in standard parameters. Truth per
             coefficient = that expression evaluated (SymPy) on s(p_true) - s(p_model), s by the
             parallel-axis theorem (withheld_cases.standard_of_body). Compared: within 20 % where
             the truth is at least 10 reported standard deviations (well determined), and within
             4 deviations everywhere.

Whole-arm effects (tilt, time_shift, coefficients) list no joints in the truth; the diagnosis
lists the joints they help, which is not compared.
"""

from __future__ import annotations

import numpy as np

from .withheld_cases import standard_of_body

TOLERANCE = 0.20  # relative, on magnitudes
NOISE_FACTOR = 1.5  # held-out RMS after, per joint, at most this many noise sigmas
WELL_DETERMINED = 10.0  # coefficient errors compared within TOLERANCE when |truth| >= this many std
COEFFICIENT_SIGMAS = 4.0  # every coefficient error within this many std of the truth

PER_JOINT = {"coulomb": ("fc", "Fc"), "viscous": ("fv", "Fv"), "armature": ("ia", "Ia"), "offset": ("offset", "b"),
             "gain": ("gain", "k-1")}
STANDARD_NAMES = ("m", "mx", "my", "mz", "XX", "XY", "XZ", "YY", "YZ", "ZZ")


def problems(truth: list[dict], d: dict, noise, p_model=None) -> list[str]:
    """truth: a case's `effects` list; d: the diagnosis JSON document; noise: the bound's unit
    per joint (the torque noise sigma, or what a perfect model leaves on the same conditioned
    data; a scalar for every joint); p_model: the model's dynamic parameters (needed only for
    the coefficients case)."""
    out = []
    selected = d["selected"]
    per_joint = {(e["effect"], e["joints"][0]): e for e in selected if e["effect"] in (*PER_JOINT, "stribeck")}
    arm = {e["effect"]: e for e in selected if e["effect"] not in (*PER_JOINT, "stribeck")}
    expected_joint, expected_arm = set(), set()

    def close(what, fitted, true):
        if fitted is None or abs(fitted - true) > TOLERANCE * abs(true):
            out.append(f"{what}: fitted {fitted}, truth {true:g} (more than {TOLERANCE:.0%} off)")

    for effect in truth:
        name, values = effect["effect"], effect["values"]
        if name in PER_JOINT:
            true_key, fit_key = PER_JOINT[name]
            for j, v in zip(effect["joints"], values[true_key]):
                expected_joint.add((name, j))
                if (name, j) in per_joint:
                    close(f"{name} on joint {j}", per_joint[(name, j)]["values"][fit_key], v)
        elif name == "stribeck":
            for j, fc, fs, vs in zip(effect["joints"], values["fc"], values["fs"], values["vs"]):
                expected_joint |= {("coulomb", j), ("stribeck", j)}
                coulomb, stribeck = per_joint.get(("coulomb", j)), per_joint.get(("stribeck", j))
                if coulomb and stribeck:
                    close(f"stribeck on joint {j}: fc", coulomb["values"]["Fc"], fc)
                    close(f"stribeck on joint {j}: fs", coulomb["values"]["Fc"] + stribeck["values"]["Fs"], fs)
                    close(f"stribeck on joint {j}: vs", stribeck["variant"]["vs"], vs)
        else:
            expected_arm.add(name)
            if name in arm:
                out += _arm_effect(name, values, arm[name], p_model)
    for key in sorted(expected_joint - set(per_joint)):
        out.append(f"{key[0]} on joint {key[1]} injected, not found")
    for key in sorted(set(per_joint) - expected_joint):
        out.append(f"{key[0]} on joint {key[1]} claimed, not injected")
    for name in sorted(expected_arm - set(arm)):
        out.append(f"{name} injected, not found")
    for name in sorted(set(arm) - expected_arm):
        out.append(f"{name} claimed, not injected")
    # The re-identified consistent link parameters (diagnosis/reidentify.py) claim that the link
    # parameters are off: only where they were.
    off = d.get("link_parameters_off")
    if off and not any(e["effect"] == "coefficients" for e in truth):
        out.append(f"link parameters off claimed (joints {off['joints']}), not injected")
    # Where the nominal residual stood above this bound, the effects must bring it down to it
    # (joints already at the noise may move by a hair either way: fitted values carry noise).
    bound = np.broadcast_to(np.asarray(noise, dtype=float), (len(d["rms_after"]),))
    for j, after in enumerate(d["rms_after"]):
        if after > NOISE_FACTOR * bound[j]:
            out.append(f"joint {j + 1}: held-out RMS after {after:.3f} > {NOISE_FACTOR} x noise {bound[j]:.3g}")
    return out


def _arm_effect(name, values, e, p_model) -> list[str]:
    out = []
    fitted = e["values"]
    if name == "payload":
        s = values["s"]
        for k, key in enumerate(("m", "mx", "my", "mz")):
            f = fitted.get(key)
            if f is None or abs(f - s[k]) > TOLERANCE * abs(s[k]):
                out.append(f"payload {key}: fitted {f}, truth {s[k]:g}")
    elif name == "time_shift":
        if abs(fitted["dt"] - values["dt"]) > TOLERANCE * abs(values["dt"]):
            out.append(f"time shift: fitted {fitted['dt']:g} s, truth {values['dt']:g} s")
    elif name == "tilt":
        change = fitted_gravity_change(fitted, nominal_gravity(values))[:2]
        true_change = (np.asarray(values["gravity"]) - nominal_gravity(values))[:2]  # a rotation: across gravity
        if np.linalg.norm(change - true_change) > TOLERANCE * np.linalg.norm(true_change):
            out.append(f"tilt: gravity change {np.round(change, 4)}, truth {np.round(true_change, 4)}")
    elif name == "coefficients":
        truth = coefficient_errors(list(fitted), values["p_true"], p_model)
        for key, true in truth.items():
            f, std = fitted[key], e["std"][key]
            if f is None:  # not identifiable from these data: nothing claimed, nothing to compare
                continue
            if abs(f - true) > COEFFICIENT_SIGMAS * std:
                out.append(f"coefficient {key}: fitted {f:g} +- {std:.2g}, truth {true:g}")
            if abs(true) >= WELL_DETERMINED * std and abs(f - true) > TOLERANCE * abs(true):
                out.append(f"coefficient {key}: fitted {f:g}, truth {true:g} (more than {TOLERANCE:.0%} off)")
        if not any(abs(true) >= WELL_DETERMINED * e["std"][k] for k, true in truth.items() if fitted[k] is not None):
            out.append("coefficients: no coefficient error is well determined")
    return out


def nominal_gravity(values) -> np.ndarray:
    """The untilted gravity: the tilted vector's length along -z (examples/lwr.yaml)."""
    return np.array([0.0, 0.0, -np.linalg.norm(values["gravity"])])


def fitted_gravity_change(fitted: dict, g0: np.ndarray) -> np.ndarray:
    n = g0 / np.linalg.norm(g0)
    seed = np.eye(3)[int(np.argmin(np.abs(n)))]
    u1 = seed - (seed @ n) * n
    u1 /= np.linalg.norm(u1)
    u2 = np.cross(n, u1)
    return fitted["dg1"] * u1 + fitted["dg2"] * u2 + fitted.get("dgn", 0.0) * n


def coefficient_errors(expressions: list[str], p_true, p_model) -> dict:
    """Each base coefficient (an expression in standard names such as `mz4 + my5`) evaluated on
    s(p_true) - s(p_model)."""
    import sympy as sp

    links = zip(np.reshape(p_true, (-1, 10)), np.reshape(p_model, (-1, 10)))
    delta = np.concatenate([standard_of_body(t) - standard_of_body(m) for t, m in links])
    subs = {sp.Symbol(f"{name}{i + 1}"): delta[10 * i + k]
            for i in range(delta.size // 10) for k, name in enumerate(STANDARD_NAMES)}
    return {e: float(sp.sympify(e).subs(subs)) for e in expressions}


# ------------------------------------------------------------------ one-line texts for tables

def truth_text(truth: list[dict]) -> str:
    parts = []
    for e in truth:
        name, joints, v = e["effect"], e["joints"], e["values"]
        if name in PER_JOINT:
            key = PER_JOINT[name][0]
            parts += [f"{name} j{j} {key} {x:g}" for j, x in zip(joints, v[key])]
        elif name == "stribeck":
            parts += [f"stribeck j{j} fc {fc:g}, fs {fs:g}, vs {vs:g}"
                      for j, fc, fs, vs in zip(joints, v["fc"], v["fs"], v["vs"])]
        elif name == "payload":
            parts.append(f"payload m {v['s'][0]:g}, mc ({', '.join(f'{x:.3g}' for x in v['s'][1:4])})")
        elif name == "tilt":
            change = np.asarray(v["gravity"]) - nominal_gravity(v)
            parts.append(f"tilt {v['angle_deg']:g} deg, dg ({', '.join(f'{x:.3f}' for x in change)})")
        elif name == "time_shift":
            parts.append(f"time shift {1e3 * v['dt']:g} ms")
        elif name == "coefficients":
            parts.append(f"masses, inertias +-{v['relative']:.0%}")
    return "; ".join(parts) or "(noise only)"


def verdict_text(d: dict) -> str:
    parts = []
    for e in d["selected"]:
        name, v = e["effect"], e["values"]
        if name in PER_JOINT:
            key = PER_JOINT[name][1]
            parts.append(f"{name} j{e['joints'][0]} {key} {v[key]:#.4g}")
        elif name == "stribeck":
            parts.append(f"stribeck j{e['joints'][0]} Fs {v['Fs']:#.4g} at vs {e['variant']['vs']:#.3g}")
        elif name == "payload":
            parts.append(f"payload m {v['m']:#.4g}, mc ({', '.join(f'{v[k]:#.3g}' for k in ('mx', 'my', 'mz'))})")
        elif name == "tilt":
            change = fitted_gravity_change(v, np.array([0.0, 0.0, -1.0]))
            angle = e["derived"]["tilt_total_deg"]
            parts.append(f"tilt {angle:#.3g} deg, dg ({', '.join(f'{x:.3f}' for x in change)})")
        elif name == "time_shift":
            parts.append(f"time shift {1e3 * v['dt']:#.3g} ms")
        elif name == "coefficients":
            known = [k for k, x in v.items() if x is not None]
            big = sorted(known, key=lambda k: -abs(v[k] / e["std"][k]) if e["std"][k] else 0)[:2]
            parts.append(f"coefficients ({len(known)} errors; largest {', '.join(f'{k} {v[k]:+.3g}' for k in big)})")
    return "; ".join(parts) or "nothing significant"
