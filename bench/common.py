"""What the benchmark scripts share: logging, the machine and compiler description, the arms."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def cpu_model() -> str:
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return model


def machine() -> str:
    return f"{os.cpu_count()} cores, {cpu_model()}, {platform.system()} {platform.machine()}"


def compiler_version(cc: str) -> str:
    res = subprocess.run([cc, "--version"], capture_output=True, text=True)
    return res.stdout.splitlines()[0].strip() if res.returncode == 0 else cc


def arm_yaml(name: str) -> Path:
    """An example name (examples/<name>.yaml) or a YAML path."""
    path = Path(name)
    if path.suffix in (".yaml", ".yml") and path.is_file():
        return path.resolve()
    path = ROOT / "examples" / f"{name}.yaml"
    if not path.is_file():
        raise SystemExit(f"no such arm: {name} (looked for {path})")
    return path


def example_arms() -> list:
    """examples/*.yaml that are robot descriptions (dyngen loads them); others are skipped."""
    from dyngen.description import load_robot

    names = []
    for path in sorted((ROOT / "examples").glob("*.yaml")):
        try:
            load_robot(path)
        except Exception as err:  # noqa: BLE001 - any failure: not an arm for the benchmarks
            log(f"skipping examples/{path.name}: not loadable as a robot description ({err})")
            continue
        names.append(path.stem)
    return names
