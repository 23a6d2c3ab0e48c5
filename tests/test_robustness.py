"""The generated C of every example arm under AddressSanitizer and UndefinedBehaviorSanitizer.

A C driver (written here from the arm's manifest) calls every generated function on 100000
states, with every argument in a heap block of exactly its documented length, so that ASan
sees any read or write past an array. States cycle through: random; all zeros; aligned axes
(every joint at a multiple of pi/2); q = +-pi/2; the joint limits; extreme but finite values;
tiny values (subnormal products); a mix of extreme and zero entries. Every output must be
finite and the sanitizers must stay silent (-fno-sanitize-recover=all: the first report aborts).

Why the extreme values stay finite in double: the generated functions have no square root and
no division but forward dynamics' by the pivots of M (it is not called with the all-zero
parameter set, where M = 0); they are polynomials in sin/cos (bounded by 1), in the prismatic joints'
q (degree <= 2 per term), in qd (degree 2), qdd (degree 1), the gravity values (degree 1) and
the parameters (degree 1 in s; degree 3 in p through m c c^T). With |q| <= 1e6 (rad or m),
|qd| <= 1e3, |qdd| <= 1e6, |gravity| <= 1e3, m <= 1e3, |c| <= 10 m and |I| <= 1e3, the largest
term is below 1e3 * (1e6)^2 * (1e3)^2 * 1e2 = 1e23 (times a few hundred terms), far from the
double limit 1.8e308: a non-finite output could only come from a bug (e.g. an uninitialised
or out-of-bounds read), not from overflow.
"""

from __future__ import annotations

import math
import os
import subprocess
from pathlib import Path

import pytest

from dyngen.runtime import library_sources
from dyngen.terms import FRICTION_FIELDS

N_STATES = 100_000
SANITIZE = ["-fsanitize=address,undefined,float-divide-by-zero,float-cast-overflow", "-fno-sanitize-recover=all",
            "-fno-omit-frame-pointer"]
ENV = {"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0", "UBSAN_OPTIONS": "print_stacktrace=1:halt_on_error=1"}

DRIVER = r"""
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "%(header)s"

typedef %(real)s real;

/* xorshift64*: the same sequence on every machine */
static unsigned long long rng_state = 0x9E3779B97F4A7C15ULL;
static double uniform(double lo, double hi)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    double u = (double)((rng_state * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
    return lo + (hi - lo) * u;
}

/* A block of exactly n values, so that ASan sees any access past its end. */
static real *block(int n)
{
    real *x = (real *)malloc((size_t)n * sizeof(real));
    if (!x) abort();
    return x;
}

static const double lower[%(dof)d] = { %(lower)s };
static const double upper[%(dof)d] = { %(upper)s };

static void fill(real *x, int n, double lo, double hi)
{
    for (int k = 0; k < n; ++k) x[k] = (real)uniform(lo, hi);
}

/* Joint values of state k: its case is k mod 8 (see the test's docstring). */
static void joints(long k, real *q, real *qd, real *qdd)
{
    const double half_pi = 1.5707963267948966;
    int n = %(dof)d;
    switch (k %% 8) {
    case 0: fill(q, n, -4, 4); fill(qd, n, -3, 3); fill(qdd, n, -10, 10); break;
    case 1: memset(q, 0, n * sizeof(real)); memset(qd, 0, n * sizeof(real)); memset(qdd, 0, n * sizeof(real)); break;
    case 2: for (int i = 0; i < n; ++i) q[i] = (real)(half_pi * (double)((int)uniform(0, 4) - 2));  /* aligned axes */
            fill(qd, n, -3, 3); fill(qdd, n, -10, 10); break;
    case 3: for (int i = 0; i < n; ++i) q[i] = (real)(uniform(0, 1) < 0.5 ? -half_pi : half_pi);
            memset(qd, 0, n * sizeof(real)); fill(qdd, n, -10, 10); break;
    case 4: for (int i = 0; i < n; ++i) q[i] = (real)(uniform(0, 1) < 0.5 ? lower[i] : upper[i]);
            fill(qd, n, -3, 3); fill(qdd, n, -10, 10); break;
    case 5: fill(q, n, -1e6, 1e6); fill(qd, n, -1e3, 1e3); fill(qdd, n, -1e6, 1e6); break;
    case 6: fill(q, n, -1e-300, 1e-300); fill(qd, n, -1e-160, 1e-160); fill(qdd, n, -1e-300, 1e-300); break;
    default:
        for (int i = 0; i < n; ++i) {
            int zero = uniform(0, 1) < 0.5;
            q[i] = zero ? 0 : (real)uniform(-1e6, 1e6);
            qd[i] = zero ? 0 : (real)uniform(-1e3, 1e3);
            qdd[i] = zero ? 0 : (real)uniform(-1e6, 1e6);
        }
    }
}

/* Dynamic parameters: masses up to 1e3 kg, centres of mass within 10 m, inertias up to 1e3
 * (not necessarily physically consistent: the functions must stay finite for any finite input).
 * Every 8th set is all zeros. */
static void parameters(long k, real *p)
{
    for (int i = 0; i < %(n_parameters)d; ++i) {
        int field = i %% 10;
        double v = field == 0 ? uniform(0, 1e3) : field < 4 ? uniform(-10, 10) : uniform(-1e3, 1e3);
        p[i] = (k %% 64) == 7 ? 0 : (real)v;
    }
}

/* Friction parameters (per joint the friction terms' fields, terms/friction.py): values up to
 * 1e3, velocity scales up to 10, with every 4th set using the plain sign and no Stribeck term
 * (every velocity 0), and the next one velocities of 1e-300 (their quotients overflow to
 * infinity inside exp and tanh, which must still give finite torques). */
static const int velocity_field[%(per_joint)d] = { %(velocity_fields)s };
static void friction_parameters(long k, real *f)
{
    for (int i = 0; i < %(per_joint)d * %(dof)d; ++i) {
        int velocity = velocity_field[i %% %(per_joint)d];
        double v = velocity ? uniform(0, 10) : uniform(0, 1e3);
        if (velocity && k %% 4 == 1) v = 0;
        if (velocity && k %% 4 == 2) v = 1e-300;
        f[i] = (real)v;
    }
}

static int finite_all(const real *x, int n)
{
    for (int k = 0; k < n; ++k)
        if (!isfinite(x[k])) return 0;
    return 1;
}

int main(int argc, char **argv)
{
    long n_states = argc > 1 ? atol(argv[1]) : 1;
    int inject = argc > 2 && strcmp(argv[2], "inject-inf") == 0;  /* proves a non-finite output is reported */
    real *q = block(%(dof)d), *qd = block(%(dof)d), *qdd = block(%(dof)d);
    real *p = block(%(n_parameters)d), *s = block(%(n_parameters)d);
    real *gravity = block(%(n_gravity_alloc)d);
    real *f = block(%(per_joint)d * %(dof)d);
%(outputs)s
    long calls = 0;
    int failed = 0;
    for (long k = 0; k < n_states && !failed; ++k) {
        joints(k, q, qd, qdd);
        if (k %% 16 == 0) parameters(k / 16, p);
        if (k %% 16 == 0) friction_parameters(k / 16, f);
        fill(gravity, %(n_gravity_alloc)d, -1e3, 1e3);
        if (inject && k == 3) qd[0] = (real)INFINITY;
%(calls)s
    }
    if (!failed) printf("%%ld states, %%ld calls, every output finite\n", n_states, calls);
    free(q); free(qd); free(qdd); free(p); free(s); free(gravity); free(f);
%(frees)s
    return failed;
}
"""


def driver_source(manifest: dict, robot) -> str:
    prefix = manifest["robot"]
    n = manifest["dof"]
    n_gravity = len(manifest["gravity_symbols"])
    limits = []
    for joint in robot.joints:
        default = (-math.pi, math.pi) if joint.revolute else (-1.0, 1.0)
        lim = joint.limits
        limits.append((lim.lower if lim and lim.lower is not None else default[0],
                       lim.upper if lim and lim.upper is not None else default[1]))
    outputs, calls, frees = [], [], []
    for f in manifest["functions"]:
        written = f.get("outputs") or [f["output"]]  # several outputs (control): each in its own block
        outs = [f"out_{f['name']}_{o['name']}" for o in written]
        sizes = [math.prod(o["shape"]) for o in written]
        for out, size in zip(outs, sizes):
            outputs.append(f"    real *{out} = block({size});")
            frees.append(f"    free({out});")
        # an input that another function's output gives, or a state array standing for one
        feeds = {"pi_full": f"out_{prefix}_pi_full_pi", "tau": f"out_{prefix}_rnea_tau", "qr_d": "qd", "qr_dd": "qdd"}
        if f["name"] == f"{prefix}_standard_from_dynamic":  # its output s feeds the dynamics functions
            outs = ["s"]
        args = [feeds.get(i["name"], i["name"]) for i in f["inputs"]] + outs
        call = f"{f['name']}({', '.join(args)})"
        finite = " && ".join(f"finite_all({out}, {size})" for out, size in zip(outs, sizes))
        # forward dynamics divides by M's pivots: not with the all-zero parameter set (M = 0)
        guard = "if (((k / 16) % 64) != 7) " if "forward_dynamics" in f["name"] else ""
        calls.append(f"        {guard}{{ {call}; ++calls; }}\n"
                     f"        if (!({finite})) {{\n"
                     f"            printf(\"{f['name']}: non-finite output at state %ld\\n\", k);\n"
                     f"            failed = 1;\n            continue;\n        }}")
    # standard_from_dynamic first: the others read s
    first = [c for c in calls if "standard_from_dynamic(" in c]
    calls = first + [c for c in calls if c not in first]
    return DRIVER % {
        "header": f"{prefix}.h", "real": f"{prefix}_real", "dof": n, "n_parameters": 10 * n,
        "per_joint": len(FRICTION_FIELDS),
        "velocity_fields": ", ".join("1" if field.kind == "velocity" else "0" for field in FRICTION_FIELDS),
        "n_gravity_alloc": max(n_gravity, 1), "lower": ", ".join(repr(float(lo)) for lo, _ in limits),
        "upper": ", ".join(repr(float(hi)) for _, hi in limits), "outputs": "\n".join(outputs),
        "calls": "\n".join(calls), "frees": "\n".join(frees)}


_objects: dict = {}  # generated folder -> its library compiled with the sanitizers (once per session)


def sanitized_library(folder: Path, build_dir: Path) -> list[str]:
    if folder not in _objects:
        build_dir.mkdir(parents=True, exist_ok=True)
        objects = []
        for source in library_sources(folder):
            obj = build_dir / (source.stem + ".o")
            subprocess.run(["cc", "-std=c99", "-O1", *SANITIZE, "-I", str(folder), "-c", str(source), "-o", str(obj)],
                           check=True, capture_output=True, text=True)
            objects.append(str(obj))
        _objects[folder] = objects
    return _objects[folder]


def build_sanitized(folder: Path, driver: str, build_dir: Path) -> Path:
    objects = sanitized_library(folder, build_dir / "library")
    (build_dir / "driver.c").write_text(driver)
    exe = build_dir / "driver"
    subprocess.run(["cc", "-std=c99", "-O1", *SANITIZE, "-I", str(folder), str(build_dir / "driver.c"), *objects,
                    "-o", str(exe), "-lm"], check=True, capture_output=True, text=True)
    return exe


def run(exe: Path, *args):
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, env={**os.environ, **ENV})


def sanitizer_report(result) -> bool:
    return any(mark in result.stderr for mark in ("runtime error", "AddressSanitizer", "LeakSanitizer"))


def test_every_function_finite_and_sanitizer_clean(built, tmp_path):
    exe = build_sanitized(built.c.folder, driver_source(built.emitted.manifest, built.robot), tmp_path)
    result = run(exe, N_STATES)
    assert not sanitizer_report(result), result.stderr[-3000:]
    assert result.returncode == 0, result.stdout + result.stderr[-3000:]
    names = [f["name"] for f in built.emitted.manifest["functions"]]
    guarded = sum("forward_dynamics" in name for name in names)  # not at the all-zero parameter sets
    zero_states = sum(1 for k in range(N_STATES) if (k // 16) % 64 == 7)
    calls = N_STATES * len(names) - guarded * zero_states
    assert result.stdout.strip() == f"{N_STATES} states, {calls} calls, every output finite"
    # the driver's finiteness check can fail: an infinite velocity at state 3 is reported
    injected = run(exe, 10, "inject-inf")
    assert injected.returncode == 1 and "non-finite output at state 3" in injected.stdout, injected.stdout


@pytest.mark.parametrize("block", ["out_lwr_rnea_tau", "out_lwr_control_c"])
def test_an_out_of_bounds_write_is_reported(block, lwr, tmp_path):
    """The sanitizer set-up can fail: a driver whose output block is one entry short aborts
    (for control(), its last output: each output has a block of its own)."""
    driver = driver_source(lwr.emitted.manifest, lwr.robot).replace(f"real *{block} = block(7);",
                                                                    f"real *{block} = block(6);")
    assert f"{block} = block(6)" in driver
    result = run(build_sanitized(lwr.c.folder, driver, tmp_path), 1)
    assert result.returncode != 0 and "heap-buffer-overflow" in result.stderr
