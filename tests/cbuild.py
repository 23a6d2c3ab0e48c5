"""Compile a generated folder under strict C99 flags (warnings are errors), then load it.

The strict compile is the check; calling the functions goes through dyngen.runtime, the
same loader the tool itself uses.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

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
    compile_objects(folder, build_dir)
    return load(folder, cache_dir=Path(build_dir))
