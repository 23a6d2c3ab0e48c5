"""Compile a generated folder under strict C99 flags (warnings are errors), then load it.

The strict compile is the check; calling the functions goes through dyngen.runtime, the
same loader the tool itself uses.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import shared_run
from dyngen.runtime import Compiled, load

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]


def compile_objects(folder: Path, build_dir: Path, extra_flags=()) -> list[Path]:
    """Each generated source compiled on its own with the strict C99 flags."""
    objects = []
    Path(build_dir).mkdir(parents=True, exist_ok=True)
    for source in sorted(Path(folder).glob("*.c")):
        obj = Path(build_dir) / (source.stem + ".o")
        subprocess.run(["cc", *STRICT, "-O1", "-fPIC", *extra_flags, "-I", str(folder), "-c", str(source),
                        "-o", str(obj)], check=True, capture_output=True, text=True)
        objects.append(obj)
    return objects


def compile_folder(folder: Path, build_dir: Path) -> Compiled:
    """The strict compile (once per distinct set of sources in a test run), then the library,
    built into the run's shared cache where there is one."""
    folder = Path(folder)
    sources = sorted(folder.glob("*.c")) + sorted(folder.glob("*.h"))
    key = shared_run.digest(*(p.name for p in sources), *(p.read_bytes() for p in sources))
    passed = shared_run.folder("strict")
    with shared_run.locked(f"strict-{key}"):
        if passed is None or not (passed / key).exists():
            compile_objects(folder, build_dir)
            if passed is not None:
                (passed / key).touch()
        return load(folder, cache_dir=shared_run.folder("libraries") or Path(build_dir))
