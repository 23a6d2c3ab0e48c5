"""What the benchmark scripts share: their set-up (on_path), arguments (arguments) and result tables
(table), logging, the machine and compiler description, the arms."""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BENCH = ROOT / "bench"


def on_path() -> Path:
    """generator/ (this checkout's dyngen, installed or not) and tests/ (the tests' simulation
    and oracles, which the benchmarks share) first on sys.path; returns the repository root."""
    for folder in (ROOT / "tests", ROOT / "generator"):
        if str(folder) not in sys.path:
            sys.path.insert(0, str(folder))
    return ROOT


def arguments(doc: str, whole: bool = False, **kwargs) -> argparse.ArgumentParser:
    """The script's argument parser, described by the first paragraph of its docstring (whole:
    by all of it, as written)."""
    if whole:
        return argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter, **kwargs)
    return argparse.ArgumentParser(description=doc.split("\n\n")[0], **kwargs)


def table(header: list, align: str = "", rows: list = ()) -> list[str]:
    """A Markdown table's lines: its header, the rule (align: "l" or "r" per column; default all
    left) and rows (lists of cells)."""
    rule = "|" + "".join("---:|" if a == "r" else "---|" for a in (align or "l" * len(header)))
    return ["| " + " | ".join(map(str, header)) + " |", rule, *("| " + " | ".join(map(str, r)) + " |" for r in rows)]


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
