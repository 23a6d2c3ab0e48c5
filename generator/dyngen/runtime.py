"""Call a generated folder's C from Python: compiled once to a shared library, loaded with cffi.

    model = load("generated/lwr")
    tau = model("rnea", q, qd, qdd, s)
    taus = model.batch("rnea", Q, QD, QDD, s)   # Q: (T, N) samples; s shared by every sample
    model32 = load("generated/lwr", real="float")   # the <ROBOT>_USE_FLOAT build, float32 arrays

A small C loop per function (written here, not part of the generated folder) runs the
samples of `batch`, so long recordings do not pay Python's per-call cost.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import tempfile
from pathlib import Path

import cffi
import numpy as np

from . import cache


REALS = {"double": np.float64, "float": np.float32}  # C type of <robot>_real -> numpy dtype


class Compiled:
    def __init__(self, folder: Path, library: Path, real: str = "double"):
        self.folder = Path(folder)
        self.manifest = json.loads((self.folder / "manifest.json").read_text())
        self.prefix = self.manifest["robot"]
        self.functions = {f["name"]: f for f in self.manifest["functions"]}
        self.real, self.dtype = real, REALS[real]
        self.ffi = cffi.FFI()
        self.ffi.cdef("\n".join(_prototype(f, real) for f in self.manifest["functions"]))
        self.ffi.cdef("\n".join(_batch_prototype(f, real) + ";" for f in self.manifest["functions"]))
        self.lib = self.ffi.dlopen(str(library))

    def _spec(self, name: str, arrays) -> dict:
        spec = self.functions[f"{self.prefix}_{name}"]
        if len(arrays) != len(spec["inputs"]):
            raise TypeError(f"{name} takes {[i['name'] for i in spec['inputs']]}")
        return spec

    def __call__(self, name: str, *arrays) -> np.ndarray:
        spec = self._spec(name, arrays)
        keep, args = [], []
        for array, inp in zip(arrays, spec["inputs"]):
            a = np.ascontiguousarray(array, dtype=self.dtype).ravel()
            if a.size != inp["length"]:
                raise ValueError(f"{name}: {inp['name']} needs {inp['length']} values, got {a.size}")
            keep.append(a)
            args.append(self.ffi.cast(f"const {self.real} *", self.ffi.from_buffer(a)))
        out = np.zeros(spec["output"]["shape"], dtype=self.dtype)
        getattr(self.lib, spec["name"])(*args, self.ffi.cast(f"{self.real} *", self.ffi.from_buffer(out)))
        return out

    def batch(self, name: str, *arrays) -> np.ndarray:
        """The function at T samples: each input is (T, length) or (length,) (the same for
        every sample); returns (T, *output shape)."""
        spec = self._spec(name, arrays)
        shaped = [np.ascontiguousarray(a, dtype=self.dtype) for a in arrays]
        counts = {a.shape[0] for a, inp in zip(shaped, spec["inputs"]) if a.ndim == 2}
        if len(counts) > 1:
            raise ValueError(f"{name}: inputs have different sample counts {sorted(counts)}")
        samples = counts.pop() if counts else 1
        keep, args = [], []
        for a, inp in zip(shaped, spec["inputs"]):
            if a.shape[-1] != inp["length"] or a.ndim not in (1, 2):
                raise ValueError(f"{name}: {inp['name']} needs {inp['length']} values per sample, got shape {a.shape}")
            keep.append(a)
            args += [self.ffi.cast(f"const {self.real} *", self.ffi.from_buffer(a)), inp["length"] if a.ndim == 2 else 0]
        out = np.zeros((samples, *spec["output"]["shape"]), dtype=self.dtype)
        getattr(self.lib, _batch_name(spec))(samples, *args, self.ffi.cast(f"{self.real} *", self.ffi.from_buffer(out)))
        return out


def _prototype(f, real: str) -> str:
    args = [f"const {real} *{a['name']}" for a in f["inputs"]] + [f"{real} *{f['output']['name']}"]
    return f"void {f['name']}({', '.join(args)});"


def _batch_name(f) -> str:
    return f"dyngen_batch_{f['name']}"


def _batch_prototype(f, real: str) -> str:
    args = ["long samples"] + [f"const {real} *{a['name']}, long {a['name']}_stride" for a in f["inputs"]]
    args.append(f"{real} *{f['output']['name']}")
    return f"void {_batch_name(f)}({', '.join(args)})"


def _batch_source(manifest, real: str) -> str:
    """C loops over samples; a stride of 0 passes the same input to every sample."""
    lines = [f'#include "{manifest["robot"]}.h"']
    for f in manifest["functions"]:
        size = 1
        for d in f["output"]["shape"]:
            size *= d
        call = ", ".join([f"{a['name']} + k * {a['name']}_stride" for a in f["inputs"]]
                         + [f"{f['output']['name']} + k * {size}"])
        lines += [f"{_batch_prototype(f, real)};", f"{_batch_prototype(f, real)}",
                  "{", "    long k;", f"    for (k = 0; k < samples; ++k) {f['name']}({call});", "}"]
    return "\n".join(lines) + "\n"


def library_sources(folder) -> list[Path]:
    """The C files of the model library (the manifest's list: the self-test is not one of them)."""
    folder = Path(folder)
    files = json.loads((folder / "manifest.json").read_text()).get("files", {})
    return [folder / name for name in files["library"]] if "library" in files else sorted(folder.glob("*.c"))


def load(folder, cache_dir: Path | None = None, real: str = "double") -> Compiled:
    """real: "double", or "float" for the build with <ROBOT>_USE_FLOAT defined. The library is
    built once into the per-user cache (dyngen.cache; `cache_dir` replaces its root) and loaded
    only after its recorded hash is checked."""
    folder = Path(folder)
    sources = library_sources(folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    flags = [f"-D{manifest['robot'].upper()}_USE_FLOAT"] if real == "float" else []
    batch = _batch_source(manifest, real)
    digest = hashlib.sha256(b"".join(p.read_bytes() for p in sources + [folder / "manifest.json"])
                            + batch.encode()).hexdigest()[:16]
    cache_dir = cache.folder("libraries", cache_dir)
    library = cache_dir / f"lib{folder.name}-{real}-{digest}.so"
    if not cache.verified(library):
        work = Path(tempfile.mkdtemp(prefix="build-", dir=cache_dir))
        try:
            tmp = work / library.name
            (work / "dyngen_batch.c").write_text(batch)
            subprocess.run(["cc", "-O2", "-std=c99", "-shared", "-fPIC", *flags, "-I", str(folder),
                            *map(str, sources), str(work / "dyngen_batch.c"), "-o", str(tmp), "-lm"],
                           check=True, capture_output=True, text=True)
            cache.install(tmp, library)
        finally:
            shutil.rmtree(work, ignore_errors=True)
    return Compiled(folder, library, real)
