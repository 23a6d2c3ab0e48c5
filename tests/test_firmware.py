"""The generated LWR library builds for microcontrollers and needs nothing but libm.

Cross-compiled with Debian's arm-none-eabi-gcc (scripts/setup.sh installs it) for a Cortex-M4F
in float and a Cortex-M7 in double, -ffreestanding, warnings as errors; the objects' undefined
symbols may only be libm's sin/cos (and GCC's sincos fusion of them) and the compiler's own
helpers (__aeabi_* on ARM; memset/memcpy, which GCC may emit even when freestanding). No heap,
no stdio, no globals (.data and .bss empty). The host build is checked the same way.
bench/bench_firmware.py measures sizes and stack use for all eight configurations.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess

import pytest
from conftest import ROOT

from dyngen.runtime import library_sources

FOLDER = ROOT / "generated" / "lwr"
LIBM = {"sin", "cos", "sinf", "cosf", "sincos", "sincosf",
        "exp", "expf", "tanh", "tanhf"}  # exp and tanh: the optional friction routine (Stribeck term, smooth sign)
COMPILER_SUPPORT = {"memset", "memcpy", "memmove"}  # GCC's freestanding requirements (gcc docs, "Standards")
HELPER = re.compile(r"__aeabi_\w+")
STRICT = ["-std=c99", "-ffreestanding", "-Wall", "-Wextra", "-Werror", "-pedantic"]
CONFIGS = {
    "cortex-m4f float -Os": (["-mcpu=cortex-m4", "-mthumb", "-mfpu=fpv4-sp-d16", "-mfloat-abi=hard", "-Os",
                              "-DLWR_USE_FLOAT", "-Wdouble-promotion"]),
    "cortex-m7 double -O2": ["-mcpu=cortex-m7", "-mthumb", "-mfpu=fpv5-d16", "-mfloat-abi=hard", "-O2"],
}


def require(tool):
    if shutil.which(tool) is None:
        message = f"{tool} not found: run scripts/setup.sh (it installs gcc-arm-none-eabi)"
        if os.environ.get("CI"):
            pytest.fail(message)  # CI installs it: a missing cross compiler is a failure there, not a skip
        pytest.skip(message)


def compile_library(cc, flags, build_dir):
    build_dir.mkdir(parents=True, exist_ok=True)
    objects = []
    for source in library_sources(FOLDER):
        obj = build_dir / (source.stem + ".o")
        subprocess.run([cc, *flags, "-I", str(FOLDER), "-c", str(source), "-o", str(obj)], check=True,
                       capture_output=True, text=True)
        objects.append(obj)
    return objects


def undefined_symbols(nm, objects) -> set:
    out = subprocess.run([nm, "-u", *map(str, objects)], check=True, capture_output=True, text=True).stdout
    return {line.split()[-1] for line in out.splitlines() if line.strip() and not line.endswith(":")}


def not_allowed(symbols) -> set:
    return {s for s in symbols if s not in LIBM | COMPILER_SUPPORT and not HELPER.fullmatch(s)}


@pytest.mark.parametrize("config", sorted(CONFIGS))
def test_cross_compiled_objects_need_only_libm_and_compiler_helpers(config, tmp_path):
    require("arm-none-eabi-gcc")
    objects = compile_library("arm-none-eabi-gcc", [*STRICT, *CONFIGS[config]], tmp_path)
    symbols = undefined_symbols("arm-none-eabi-nm", objects)
    assert symbols, "nm saw no undefined symbol at all: sin/cos must be there"
    assert not not_allowed(symbols), not_allowed(symbols)
    if "float" in config:  # the float build computes in float: no double routine, no double arithmetic helper
        assert {"sinf", "cosf"} <= symbols and not symbols & {"sin", "cos"}
        assert not any(s.startswith("__aeabi_d") for s in symbols), symbols
    sizes = subprocess.run(["arm-none-eabi-size", *map(str, objects)], check=True, capture_output=True,
                           text=True).stdout.splitlines()[1:]
    assert all(int(line.split()[1]) == 0 and int(line.split()[2]) == 0 for line in sizes), sizes  # .data, .bss


@pytest.mark.parametrize("flags", [["-O2", "-fPIC"], ["-O2", "-DLWR_USE_FLOAT"]], ids=["double", "float"])
def test_host_objects_need_only_libm(flags, tmp_path):
    """The ordinary hosted build (not freestanding, as dyngen.runtime compiles it): GCC may fuse
    sin and cos into sincos and turn a zeroing loop into memset, nothing more."""
    hosted = [f for f in STRICT if f != "-ffreestanding"]
    objects = compile_library("cc", [*hosted, *flags], tmp_path)
    symbols = undefined_symbols("nm", objects)
    assert symbols and not not_allowed(symbols), not_allowed(symbols)


def test_the_symbol_check_catches_io_and_heap(tmp_path):
    """The check above can fail: a library source calling malloc and printf is refused."""
    source = tmp_path / "bad.c"
    source.write_text("#include <stdio.h>\n#include <stdlib.h>\n"
                      "void f(void) { void *p = malloc(8); printf(\"%p\\n\", p); free(p); }\n")
    subprocess.run(["cc", "-c", str(source), "-o", str(tmp_path / "bad.o")], check=True)
    assert not_allowed(undefined_symbols("nm", [tmp_path / "bad.o"])) >= {"malloc", "free"}
