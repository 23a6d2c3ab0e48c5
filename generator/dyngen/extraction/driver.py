"""Build the static NLopt driver (driver_cpp/driver.cpp) for one arm and run it on a problem file."""

from __future__ import annotations

import hashlib
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import cache
from ..errors import DriverError
from .problem import Options, Problem, Stage
from .protocol import problem_text, read_result_text


def eigen_include() -> str:
    for candidate in ("/usr/include/eigen3", "/usr/local/include/eigen3"):
        if Path(candidate, "Eigen", "Dense").exists():
            return candidate
    try:
        flags = subprocess.run(["pkg-config", "--cflags", "eigen3"], capture_output=True, text=True, check=True)
        return flags.stdout.strip().removeprefix("-I")
    except (OSError, subprocess.CalledProcessError):
        raise DriverError("Eigen 3 not found: run scripts/setup.sh (apt package libeigen3-dev)") from None


DRIVER = Path(__file__).resolve().parent / "driver_cpp"  # the static driver's sources (package data)
CORE_SOURCES = ("driver.cpp", "protocol.hpp", "robot.h")


def _digest(paths) -> str:
    return hashlib.sha256(b"".join(Path(p).read_bytes() for p in paths)).hexdigest()[:16]


def _cached(target: Path, make) -> Path:
    """`target` from the cache while its recorded hash still matches; else make(work, built)
    builds it in a private temporary folder beside it, and it is installed (dyngen.cache)."""
    if cache.verified(target):
        return target
    work = Path(tempfile.mkdtemp(prefix="build-", dir=target.parent))
    try:
        built = work / target.name
        make(work, built)
        cache.install(built, target)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return target


def build_core(cache_dir: Path | None = None) -> Path:
    """The static driver (driver.cpp, Eigen and NLopt: the slow part) compiled once per user and
    source content into the per-user cache; every arm links this object."""
    folder = cache.folder("drivers", cache_dir)

    def make(work, built):
        _run(["c++", "-O2", "-std=c++17", "-I", str(DRIVER), "-I", eigen_include(), "-c", str(DRIVER / "driver.cpp"),
              "-o", str(built)])

    return _cached(folder / f"driver-{_digest(DRIVER / name for name in CORE_SOURCES)}.o", make)


def build(folder: Path, cache_dir: Path | None = None) -> Path:
    """The extractor of the arm generated in `folder`: the static driver (build_core) linked
    with the arm's generated C (<robot>_parameters.c, <robot>_kinds.h) and robot.c, once per
    content into the per-user cache (dyngen.cache; `cache_dir` replaces its root); returns the
    executable, its recorded hash checked."""
    folder = Path(folder)
    name = folder.name
    core = build_core(cache_dir)
    parameters, robot_c = folder / f"{name}_parameters.c", DRIVER / "robot.c"
    sources = [parameters, folder / f"{name}.h", folder / f"{name}_kinds.h", robot_c]

    def make(work, built):
        objects = [work / "parameters.o", work / "robot.o"]
        _run(["cc", "-O2", "-std=c99", "-I", str(folder), "-c", str(parameters), "-o", str(objects[0])])
        _run(["cc", "-O2", "-std=c99", "-I", str(folder), "-I", str(DRIVER), f'-DDYNGEN_KINDS_H="{name}_kinds.h"',
              "-c", str(robot_c), "-o", str(objects[1])])
        if not cache.verified(core):  # checked again right before it is linked in
            raise DriverError(f"{core} changed after it was built; run again to rebuild it")
        _run(["c++", str(core), *map(str, objects), "-o", str(built), "-lnlopt", "-lpthread"])

    return _cached(cache.folder("drivers", cache_dir) / f"{name}_extract-{_digest([core, *sources])}", make)


def standalone_files(folder: Path) -> dict:
    """The driver as a standalone program for the arm generated in `folder` (outside that
    firmware folder: it needs NLopt and threads): file name -> text."""
    name = Path(folder).name
    files = {source.name: source.read_text() for source in sorted(DRIVER.iterdir())
             if source.suffix in (".cpp", ".hpp", ".h", ".c")}
    files["BUILD.txt"] = (
        f"The extractor driver of {name} (dyngen extract builds the same program in its cache).\n"
        f"With the generated folder of {name} as MODEL (it holds {name}.h, {name}_parameters.c, {name}_kinds.h):\n\n"
        "  c++ -O2 -std=c++17 -I. -I/usr/include/eigen3 -c driver.cpp\n"
        f"  cc -O2 -std=c99 -I. -IMODEL -DDYNGEN_KINDS_H='\"{name}_kinds.h\"' -c robot.c MODEL/{name}_parameters.c\n"
        f"  c++ driver.o robot.o {name}_parameters.o -lnlopt -lpthread -o {name}_extract\n\n"
        f"  ./{name}_extract PROBLEM_FILE RESULT_FILE   (the problem file: extraction/protocol.py)\n")
    return files


def _run(cmd):
    try:
        subprocess.run(cmd, check=True, capture_output=True, text=True)
    except FileNotFoundError:
        raise DriverError(f"{cmd[0]} not found: run scripts/setup.sh") from None
    except subprocess.CalledProcessError as err:
        raise DriverError(f"building the extractor failed:\n{err.stderr[-2000:]}") from None


@dataclass
class StageResult:
    name: str
    status: str  # "ok" | "infeasible"
    restarts: int
    consistent: int
    restart_costs: np.ndarray
    restart_violations: np.ndarray
    p: np.ndarray | None = None
    fit_cost: float = np.nan
    cost: float = np.nan
    violation: float = np.nan
    residuals: dict | None = None  # kind -> W pi(p) - v
    lambda_min: np.ndarray | None = None


def run(exe: Path, problem: Problem, stage: Stage, options: Options, on_progress=None) -> StageResult:
    with tempfile.TemporaryDirectory(prefix="dyngen-extract-") as tmp:
        problem_file, result_file = Path(tmp, "problem.txt"), Path(tmp, "result.txt")
        problem_file.write_text(problem_text(problem, stage, options))
        proc = subprocess.Popen([str(exe), str(problem_file), str(result_file)], stderr=subprocess.PIPE, text=True)
        errors = []
        for line in proc.stderr:
            if line.startswith("progress ") and on_progress:
                done, total = map(int, line.split()[1:3])
                on_progress(done, total)
            elif not line.startswith("progress "):
                errors.append(line)
        if proc.wait() != 0:
            raise DriverError("extractor failed: " + "".join(errors))
        return parse(stage.name, result_file.read_text())


def parse(name: str, text: str) -> StageResult:
    """The stage's result from the driver's result file (extraction/protocol.py, RESULT)."""
    fields = read_result_text(text)
    result = StageResult(name, fields["status"], fields["restarts"], fields["consistent"], fields["restart_costs"],
                         fields["restart_violations"], fields["parameters"])
    if result.status == "ok":
        result.fit_cost = fields["fit_cost"]
        result.cost = fields["cost"]
        result.violation = fields["violation"]
        result.residuals = fields["residuals"]
        result.lambda_min = fields["lambda_min"]
    return result
