"""Call a generated folder's C from Python: compiled once to a shared library, loaded with cffi.

    model = dyngen.load("generated/lwr")          # (this module's load)
    tau = model.rnea(q, qd, qdd, s)               # one method per function of the manifest
    g, M, c = model.control(q, qd, s)             # several outputs: a tuple
    taus = model.rnea(Q, QD, QDD, s)              # Q: (T, N) samples; s shared by every sample
    tau = model("rnea", q, qd, qdd, s)            # the same by name; model.batch(name, ...) for samples
    model32 = dyngen.load("generated/lwr", real="float")   # the <ROBOT>_USE_FLOAT build, float32 arrays

A small C loop per function (written here, not part of the generated folder) runs the
samples of `batch`, so long recordings do not pay Python's per-call cost.
"""

from __future__ import annotations

import hashlib
import inspect
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
        for spec in self.manifest["functions"]:
            short = spec["name"][len(self.prefix) + 1:]
            if hasattr(self, short):
                raise ValueError(f"{folder}: function {spec['name']} would hide the loader's own {short!r}")
            setattr(self, short, _method(self, short, spec))

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
        outs = [np.zeros(o["shape"], dtype=self.dtype) for o in outputs(spec)]
        getattr(self.lib, spec["name"])(*args, *(self.ffi.cast(f"{self.real} *", self.ffi.from_buffer(o)) for o in outs))
        return outs[0] if len(outs) == 1 else tuple(outs)

    def batch(self, name: str, *arrays) -> np.ndarray:
        """The function at T samples: each input is (T, length) or (length,) (the same for
        every sample); returns (T, *output shape) (a tuple of them for several outputs)."""
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
        outs = [np.zeros((samples, *o["shape"]), dtype=self.dtype) for o in outputs(spec)]
        getattr(self.lib, _batch_name(spec))(samples, *args,
                                             *(self.ffi.cast(f"{self.real} *", self.ffi.from_buffer(o)) for o in outs))
        return outs[0] if len(outs) == 1 else tuple(outs)


def _method(model: Compiled, short: str, spec: dict):
    """model.<short>(*inputs): one call, or `batch` when an input has a leading sample axis."""
    names = [i["name"] for i in spec["inputs"]]

    def method(*arrays, **named):
        if named:
            unknown = set(named) - set(names[len(arrays):])
            if unknown:
                raise TypeError(f"{short}() got unexpected or repeated arguments {sorted(unknown)}; takes {names}")
            missing = [n for n in names[len(arrays):] if n not in named]
            if missing:
                raise TypeError(f"{short}() missing {missing}")
            arrays = arrays + tuple(named[n] for n in names[len(arrays):])
        lengths = [i["length"] for i in spec["inputs"]]
        per_sample = any(np.ndim(a) == 2 and np.shape(a)[-1] == n for a, n in zip(arrays, lengths))
        return model.batch(short, *arrays) if per_sample else model(short, *arrays)

    shapes = ", ".join(f"{o['name']} {tuple(o['shape'])}" for o in outputs(spec))
    inputs = "\n".join(f"    {i['name']} [{i['length']}]: {i['meaning']}" for i in spec["inputs"])
    method.__name__ = method.__qualname__ = short
    method.__doc__ = (f"{spec['doc']}\n\n{short}({', '.join(names)}) -> {shapes}\n{inputs}\n"
                      f"Each input may carry a leading axis of T samples: the outputs then do too.")
    method.__signature__ = inspect.Signature(
        [inspect.Parameter(n, inspect.Parameter.POSITIONAL_OR_KEYWORD) for n in names])
    return method


def outputs(spec) -> list:
    """A manifest function's output arrays, in argument order (older manifests list one)."""
    return spec.get("outputs") or [spec["output"]]


def _prototype(f, real: str) -> str:
    args = [f"const {real} *{a['name']}" for a in f["inputs"]] + [f"{real} *{o['name']}" for o in outputs(f)]
    return f"void {f['name']}({', '.join(args)});"


def _batch_name(f) -> str:
    return f"dyngen_batch_{f['name']}"


def _batch_prototype(f, real: str) -> str:
    args = ["long samples"] + [f"const {real} *{a['name']}, long {a['name']}_stride" for a in f["inputs"]]
    args += [f"{real} *{o['name']}" for o in outputs(f)]
    return f"void {_batch_name(f)}({', '.join(args)})"


def _batch_source(manifest, real: str) -> str:
    """C loops over samples; a stride of 0 passes the same input to every sample."""
    lines = [f'#include "{manifest["robot"]}.h"']
    for f in manifest["functions"]:
        call = ", ".join([f"{a['name']} + k * {a['name']}_stride" for a in f["inputs"]]
                         + [f"{o['name']} + k * {_size(o['shape'])}" for o in outputs(f)])
        lines += [f"{_batch_prototype(f, real)};", f"{_batch_prototype(f, real)}",
                  "{", "    long k;", f"    for (k = 0; k < samples; ++k) {f['name']}({call});", "}"]
    return "\n".join(lines) + "\n"


def _size(shape) -> int:
    size = 1
    for d in shape:
        size *= d
    return size


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
