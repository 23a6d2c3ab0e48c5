"""Compile a generated folder with cffi (strict C99 flags) and load it."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import cffi
import numpy as np

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]


def compile_objects(folder: Path, build_dir: Path, extra_flags=()) -> list[Path]:
    """Each generated source compiled on its own with the strict C99 flags (warnings are errors)."""
    objects = []
    for source in sorted(Path(folder).glob("*.c")):
        obj = Path(build_dir) / (source.stem + ".o")
        subprocess.run(["cc", *STRICT, "-O1", "-fPIC", *extra_flags, "-I", str(folder), "-c", str(source),
                        "-o", str(obj)], check=True, capture_output=True, text=True)
        objects.append(obj)
    return objects


class Compiled:
    """The compiled functions of one generated folder, called with numpy arrays."""

    def __init__(self, folder: Path, module, manifest: dict):
        self.folder, self.ffi, self.lib, self.manifest = folder, module.ffi, module.lib, manifest
        self.functions = {f["name"]: f for f in manifest["functions"]}
        self.prefix = manifest["robot"]

    def __call__(self, short_name: str, *arrays):
        spec = self.functions[f"{self.prefix}_{short_name}"]
        args = []
        for array, inp in zip(arrays, spec["inputs"]):
            a = np.ascontiguousarray(array, dtype=np.float64)
            assert a.size == inp["length"], (short_name, inp["name"], a.size, inp["length"])
            args.append(self.ffi.cast("const double *", self.ffi.from_buffer(a)))
        assert len(arrays) == len(spec["inputs"]), short_name
        out = np.zeros(spec["output"]["shape"], dtype=np.float64)
        getattr(self.lib, spec["name"])(*args, self.ffi.cast("double *", self.ffi.from_buffer(out)))
        return out


def prototypes(manifest: dict, real: str = "double") -> str:
    lines = []
    for f in manifest["functions"]:
        args = [f"const {real} *{a['name']}" for a in f["inputs"]] + [f"{real} *{f['output']['name']}"]
        lines.append(f"void {f['name']}({', '.join(args)});")
    return "\n".join(lines)


def compile_folder(folder: Path, build_dir: Path, extra_flags=()) -> Compiled:
    folder, build_dir = Path(folder), Path(build_dir)
    manifest = json.loads((folder / "manifest.json").read_text())
    name = manifest["robot"]
    ffi = cffi.FFI()
    ffi.cdef(prototypes(manifest))
    module_name = f"_dyngen_{name}_{abs(hash(str(build_dir))) % 10**8}"
    build_dir.mkdir(parents=True, exist_ok=True)
    objects = compile_objects(folder, build_dir, extra_flags)
    ffi.set_source(module_name, f'#include "{name}.h"', include_dirs=[str(folder)],
                   extra_objects=[str(o) for o in objects], libraries=["m"])
    library = ffi.compile(tmpdir=str(build_dir), verbose=False)
    spec = importlib.util.spec_from_file_location(module_name, library)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    spec.loader.exec_module(module)
    return Compiled(folder, module, manifest)
