"""The command line: help, bad input, atomic and deterministic output, checked-in generated/."""

from __future__ import annotations

import subprocess
import sys

import pytest
from cbuild import compile_objects
from conftest import ROOT

from dyngen.runtime import library_sources

LWR = ROOT / "examples" / "lwr.yaml"


def dyngen(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "dyngen.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd)


def test_help_on_every_command():
    for args in (["--help"], ["generate", "--help"]):
        result = dyngen(*args)
        assert result.returncode == 0 and "ROBOT.yaml" in result.stdout


BAD = {
    "malformed YAML": ("joints: [", "lwr.yaml: line"),
    "unknown joint type": ("{type: revolute, a: 0, alpha: \"pi/2\"", "{type: helical, a: 0, alpha: \"pi/2\""),
    "alpha not a number": ('alpha: "-pi/2", d: 0.4', 'alpha: "ninety", d: 0.4'),
    "bounds LB > UB": ("{m: [0, 6], c: [[-0.05, 0.05], [-0.2, 0.05]", "{m: [6, 0], c: [[-0.05, 0.05], [-0.2, 0.05]"),
    "unknown field": ("dh: standard", "dh: standard\ncolour: orange"),
    "wrong number of bounds": ("total_mass: [13, 19]", "total_mass: [13]"),
}
EXPECTED = {
    "malformed YAML": "lwr.yaml: line",
    "unknown joint type": 'lwr.yaml: joints[0].type: unknown joint type; expected "revolute" or "prismatic", got "helical"',
    "alpha not a number": 'lwr.yaml: joints[2].alpha: expected a number or an expression of pi, got "ninety"',
    "bounds LB > UB": "lwr.yaml: parameters.bounds[0].m: LB > UB (6.0 > 0.0)",
    "unknown field": "lwr.yaml: colour: unknown field",
    "wrong number of bounds": "lwr.yaml: parameters.total_mass: expected 2 entries, got 1",
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_one_line_error_nothing_written(case, tmp_path):
    old, new = BAD[case]
    text = LWR.read_text()
    if case == "malformed YAML":
        text = text + "\n" + old + "\n"
    else:
        assert old in text, old
        text = text.replace(old, new, 1)
    (tmp_path / "lwr.yaml").write_text(text)
    out = tmp_path / "out"
    result = dyngen(tmp_path / "lwr.yaml", "-o", out)
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert EXPECTED[case] in lines[0], lines[0]
    assert not out.exists()


def test_arm_without_gravity_coefficients_is_one_line(tmp_path):
    """A horizontal SCARA: gravity never acts on its joints, so there is no gravity coefficient."""
    (tmp_path / "scara.yaml").write_text(
        "name: scara\ndh: standard\ngravity: [0, 0, -9.81]\njoints:\n"
        "  - {type: revolute, a: 0.4, alpha: 0, d: 0.3, theta: 0}\n"
        "  - {type: revolute, a: 0.3, alpha: 0, d: 0, theta: 0}\n")
    result = dyngen("generate", tmp_path / "scara.yaml", "-o", tmp_path / "out", "-q")
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "scara.yaml: gravity: no joint of this arm moves against gravity" in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_missing_file_is_one_line():
    result = dyngen("no/such/robot.yaml")
    assert result.returncode != 0 and len(result.stderr.strip().splitlines()) == 1
    assert "no/such/robot.yaml" in result.stderr


def test_failed_run_leaves_previous_output_untouched(tmp_path):
    out = tmp_path / "out"
    assert dyngen(LWR, "-o", out, "-q").returncode == 0
    before = {p.name: p.read_bytes() for p in (out / "lwr").iterdir()}
    bad = tmp_path / "lwr.yaml"
    bad.write_text(LWR.read_text().replace("dh: standard", "dh: sideways"))
    assert dyngen(bad, "-o", out).returncode != 0
    assert {p.name: p.read_bytes() for p in (out / "lwr").iterdir()} == before
    assert sorted(p.name for p in out.iterdir()) == ["lwr"]  # no staging folders left behind


def test_output_is_byte_identical_across_runs(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    assert dyngen(LWR, "-o", a, "-q").returncode == 0
    assert dyngen(LWR, "-o", b, "-q").returncode == 0
    files = sorted(p.name for p in (a / "lwr").iterdir())
    assert files == sorted(p.name for p in (b / "lwr").iterdir())
    for name in files:
        assert (a / "lwr" / name).read_bytes() == (b / "lwr" / name).read_bytes(), name


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "generated").iterdir()))
def test_checked_in_generated_folders_are_up_to_date(name, tmp_path):
    """Fails when the generator changed and a folder of generated/ was not regenerated
    (`dyngen generate examples/<name>.yaml`); every checked-in folder is guarded."""
    assert dyngen("generate", ROOT / "examples" / f"{name}.yaml", "-o", tmp_path, "-q").returncode == 0
    checked_in = ROOT / "generated" / name
    fresh = {p.name: p.read_bytes() for p in (tmp_path / name).iterdir()}
    assert sorted(fresh) == sorted(p.name for p in checked_in.iterdir())
    stale = [file for file, data in fresh.items() if (checked_in / file).read_bytes() != data]
    assert not stale, f"generated/{name} is out of date: {stale}; run `dyngen generate examples/{name}.yaml`"


def test_checked_in_c_is_clean_under_strict_c99_in_double_and_float(tmp_path):
    folder = ROOT / "generated" / "lwr"
    compile_objects(folder, tmp_path)
    compile_objects(folder, tmp_path, ["-DLWR_USE_FLOAT", "-Wdouble-promotion"])


def test_generated_code_needs_no_heap_io_or_globals():
    """The library sources; the self-test (lwr_selftest.c) prints its verdict, so it is not one of them."""
    for source in library_sources(ROOT / "generated" / "lwr"):
        text = source.read_text()
        for word in ("malloc", "free(", "printf", "static ", "#include <stdio.h>"):
            assert word not in text, (source.name, word)
        assert [line for line in text.splitlines() if line.startswith("#include")] == ['#include "lwr.h"']
