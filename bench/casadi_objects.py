"""CasADi's generated C, one file per casadi.Function, each compiled once and cached.

gcc -O2 on one translation unit holding every CasADi function of an arm (2.2 MB of C for the
LWR's controller functions) ran for over 20 minutes under load; one file per function compiles
in seconds (the largest, LWR fd_derivatives, 7 s unloaded) and the files compile in parallel.

The objects are cached by the SHA-256 of (C source, compiler version, command) in dyngen's
private per-user cache (dyngen.cache: ~/.cache/dyngen/bench-casadi, 0700, every object's
hash recorded and checked before it is linked), never in a shared /tmp path: the names are
predictable, and a planted object would be linked into the benchmark and run.

    objects = compile_functions(fns, folder, cc, flags)   # {function name: (header, object)}
"""
from __future__ import annotations

import fcntl
import hashlib
import os
import shlex
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import casadi as ca

from common import compiler_version, log


def write_function(fn: ca.Function, folder: Path) -> tuple[Path, Path]:
    """<folder>/<name>.c and .h for one function (cse=True is the function's own option)."""
    cg = ca.CodeGenerator(f"{fn.name()}.c", {"with_header": True, "casadi_real": "double"})
    cg.add(fn)
    folder.mkdir(parents=True, exist_ok=True)
    cg.generate(str(folder) + "/")
    return folder / f"{fn.name()}.c", folder / f"{fn.name()}.h"


def _cached_object(src: Path, cc: str, flags: list, version: str) -> Path:
    from dyngen import cache

    cmd = [cc, "-std=c99", *flags, "-c"]
    key = hashlib.sha256("\0".join([src.read_text(), version, shlex.join(cmd)]).encode()).hexdigest()[:20]
    target = cache.folder("bench-casadi") / f"{src.stem}-{key}.o"
    with open(target.with_name(target.name + ".lock"), "w") as lock:  # two runs wanting it: one compiles, one waits
        fcntl.flock(lock, fcntl.LOCK_EX)
        if cache.verified(target):
            return target
        log(f"CasADi: compiling {src.name} ({src.stat().st_size // 1024} kB) ...")
        built = target.with_name(f"{target.name}.{os.getpid()}.tmp.o")
        res = subprocess.run(["nice", "-n", "10", *cmd, str(src), "-o", str(built)], capture_output=True, text=True)
        if res.returncode != 0:
            raise SystemExit(f"compiling {src} failed:\n{res.stderr}")
        return cache.install(built, target)


def compile_functions(fns: list, folder: Path, cc: str, flags: list, jobs: int = 2) -> dict:
    """{function name: (header, object)}: each function's C written into folder, compiled (or
    found in the cache), `jobs` compiles at a time, the largest first."""
    sources = {fn.name(): write_function(fn, folder) for fn in fns}
    version = compiler_version(cc)
    order = sorted(sources, key=lambda k: -sources[k][0].stat().st_size)
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        objects = dict(zip(order, pool.map(lambda k: _cached_object(sources[k][0], cc, flags, version), order)))
    return {k: (sources[k][1], objects[k]) for k in sources}


def info(fns: list) -> dict:
    """{function name: {iw, w, n_instructions}} (work sizes for the caller's buffers)."""
    return {f.name(): {"iw": int(f.sz_iw()), "w": int(f.sz_w()), "n_instructions": int(f.n_instructions())}
            for f in fns}
