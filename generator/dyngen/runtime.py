"""Call a generated folder's C from Python: compiled once to a shared library, loaded with cffi.

    model = load("generated/lwr")
    tau = model("rnea", q, qd, qdd, s)
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import cffi
import numpy as np


class Compiled:
    def __init__(self, folder: Path, library: Path):
        self.folder = Path(folder)
        self.manifest = json.loads((self.folder / "manifest.json").read_text())
        self.prefix = self.manifest["robot"]
        self.functions = {f["name"]: f for f in self.manifest["functions"]}
        self.ffi = cffi.FFI()
        self.ffi.cdef("\n".join(_prototype(f) for f in self.manifest["functions"]))
        self.lib = self.ffi.dlopen(str(library))

    def __call__(self, name: str, *arrays) -> np.ndarray:
        spec = self.functions[f"{self.prefix}_{name}"]
        if len(arrays) != len(spec["inputs"]):
            raise TypeError(f"{name} takes {[i['name'] for i in spec['inputs']]}")
        keep, args = [], []
        for array, inp in zip(arrays, spec["inputs"]):
            a = np.ascontiguousarray(array, dtype=np.float64).ravel()
            if a.size != inp["length"]:
                raise ValueError(f"{name}: {inp['name']} needs {inp['length']} values, got {a.size}")
            keep.append(a)
            args.append(self.ffi.cast("const double *", self.ffi.from_buffer(a)))
        out = np.zeros(spec["output"]["shape"], dtype=np.float64)
        getattr(self.lib, spec["name"])(*args, self.ffi.cast("double *", self.ffi.from_buffer(out)))
        return out


def _prototype(f) -> str:
    args = [f"const double *{a['name']}" for a in f["inputs"]] + [f"double *{f['output']['name']}"]
    return f"void {f['name']}({', '.join(args)});"


def load(folder, cache_dir: Path | None = None) -> Compiled:
    folder = Path(folder)
    sources = sorted(folder.glob("*.c"))
    digest = hashlib.sha256(b"".join(p.read_bytes() for p in sources + [folder / "manifest.json"])).hexdigest()[:16]
    cache_dir = Path(cache_dir or Path(tempfile.gettempdir()) / "dyngen-libraries")
    library = cache_dir / f"lib{folder.name}-{digest}.so"
    if not library.exists():
        cache_dir.mkdir(parents=True, exist_ok=True)
        work = Path(tempfile.mkdtemp(prefix="build-", dir=cache_dir))
        try:
            tmp = work / library.name
            subprocess.run(["cc", "-O2", "-std=c99", "-shared", "-fPIC", "-I", str(folder), *map(str, sources),
                            "-o", str(tmp), "-lm"], check=True, capture_output=True, text=True)
            os.replace(tmp, library)
        finally:
            shutil.rmtree(work, ignore_errors=True)
    return Compiled(folder, library)
