"""Step options (dyngen.options): for the extraction step, the command line's defaults, the
YAML block's defaults and the dataclass defaults are the same, every option can be set either
way with the same result, and both refuse the same out-of-range values."""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from dataclasses import fields

import pytest
import yaml
from conftest import ROOT

from dyngen.description import load_robot
from dyngen.errors import InputError
from dyngen.extraction.options import Options
from dyngen.options import add_arguments, default_of, flag_of, resolve

LWR = ROOT / "examples" / "lwr.yaml"
CHANGED = {"procedure": "two-stage", "restarts": 5, "seed": 7, "threads": 2, "global_algorithm": "none",
           "global_maxeval": 11, "local_maxeval": 13, "hops": 3, "hop_size": 0.25, "margin": 2e-6,
           "mass_margin": 0.01, "tolerance": 1e-8, "identities": ("I7xz = c7x*c7z*m7",)}


def parser():
    p = argparse.ArgumentParser()
    add_arguments(p, Options)
    return p


def robot_with(tmp_path, block):
    doc = yaml.safe_load(LWR.read_text())
    doc.pop("extraction", None)
    if block is not None:
        doc["extraction"] = block
    path = tmp_path / "lwr.yaml"
    path.write_text(yaml.safe_dump(doc))
    return load_robot(path)


def test_every_option_is_changed_by_the_test():
    assert sorted(CHANGED) == sorted(f.name for f in fields(Options))
    assert all(CHANGED[f.name] != default_of(f) for f in fields(Options))


def test_command_line_defaults_equal_yaml_defaults_equal_dataclass_defaults(tmp_path):
    assert resolve(Options, parser().parse_args([]), {}) == Options()
    assert resolve(Options, None, robot_with(tmp_path, None).extraction) == Options()
    assert resolve(Options, parser().parse_args([]), robot_with(tmp_path, {}).extraction) == Options()


def test_the_dyngen_help_shows_the_dataclass_defaults():
    text = subprocess.run([sys.executable, "-m", "dyngen.cli", "extract", "--help"], capture_output=True,
                          text=True, check=True).stdout
    text = re.sub(r"\s+", " ", text)
    for f in fields(Options):
        default = default_of(f)
        shown = "none" if default == () else str(default)
        assert re.search(re.escape(flag_of(f)) + r" .*?\(default: " + re.escape(shown) + r"\)", text), f.name


def test_every_option_set_on_the_command_line_or_in_the_yaml_gives_the_same_options(tmp_path):
    argv = []
    for f in fields(Options):
        values = CHANGED[f.name] if f.metadata["repeat"] else [CHANGED[f.name]]
        for v in values:
            argv += [flag_of(f), str(v)]
    from_cli = resolve(Options, parser().parse_args(argv), {})
    block = {k: list(v) if isinstance(v, tuple) else v for k, v in CHANGED.items()}
    from_yaml = resolve(Options, None, robot_with(tmp_path, block).extraction)
    assert from_cli == from_yaml == Options(**CHANGED)


def test_the_command_line_overrides_the_yaml(tmp_path):
    robot = robot_with(tmp_path, {"restarts": 5, "seed": 7})
    options = resolve(Options, parser().parse_args(["--restarts", "9"]), robot.extraction)
    assert (options.restarts, options.seed) == (9, 7)


@pytest.mark.parametrize("name, bad", [("restarts", 0), ("seed", 2**31), ("margin", -1.0), ("hop_size", 2.0),
                                       ("procedure", "three-stage"), ("threads", 1.5)])
def test_both_refuse_the_same_values(tmp_path, name, bad):
    with pytest.raises(InputError, match=f"extraction.{name}"):
        robot_with(tmp_path, {name: bad})
    flag = flag_of(next(f for f in fields(Options) if f.name == name))
    with pytest.raises(SystemExit):
        parser().parse_args([flag, str(bad)])
