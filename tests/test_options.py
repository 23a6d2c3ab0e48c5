"""Step options (dyngen.options): for the extraction step, the command line's defaults, the
YAML block's defaults and the dataclass defaults are the same, every option can be set either
way with the same result, and both refuse the same out-of-range values. For identify, diagnose
and excite (no YAML block), the real parser's defaults are the dataclasses' and every option
is set by its flag."""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from dataclasses import fields

import pytest
import yaml
from conftest import ROOT

from dyngen.data import Conditioning
from dyngen.description import load_robot
from dyngen.diagnosis.diagnose_options import Options as DiagnosisOptions
from dyngen.errors import InputError
from dyngen.commands.excite import Sampling
from dyngen.commands.excite import parser as excite_parser
from dyngen.excitation.design import Settings
from dyngen.description.extraction_options import Options
from dyngen.identification.consistent import ConsistentOptions
from dyngen.identification.identify_options import Options as IdentifyOptions
from dyngen.commands.diagnose import parser as diagnose_parser
from dyngen.commands.identify import parser as identify_parser
from dyngen.options import add_arguments, default_of, flag_of, options_of, resolve

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

# The other steps: identify, diagnose and excite read no YAML block; their flags come from
# their dataclasses, through the commands' real parsers.

REQUIRED = {"identify": ["lwr.yaml", "--data", "a.csv"], "diagnose": ["lwr.yaml", "--data", "a.csv", "--params", "p.yaml"],
            "excite": ["lwr.yaml"]}
STEPS = {"identify": (identify_parser, (IdentifyOptions, ConsistentOptions, Conditioning)),
         "diagnose": (diagnose_parser, (DiagnosisOptions, Conditioning)),
         "excite": (excite_parser, (Settings, Sampling))}
# A value other than the default for every option of these steps, as typed on the command line.
TYPED = {"kind": ("gravity", "gravity"), "ols": (None, True), "consistent": (None, True),
         "friction": ("coulomb, ripple", ("coulomb", "ripple")), "candidates": ("tilt", ("tilt",)), "smoothing": ("0.01", 0.01),
         "regularisation": ("3", 3.0), "tilt": (None, True), "cutoff": ("none", None), "order": ("2", 2),
         "differentiate": (None, True), "effects": ("offset,gain", ("offset", "gain")), "min_gain": ("0.1", 0.1),
         "sign_velocity": ("0.01", 0.01), "reidentify": (None, True), "seed": ("7", 7), "period": ("5", 5.0),
         "harmonics": ("3", 3), "margin": ("0.5", 0.5), "max_iterations": ("9", 9), "criterion": ("logdet", "logdet"),
         "rate": ("200", 200.0), "periods": ("2", 2)}


@pytest.mark.parametrize("step", sorted(STEPS))
def test_command_line_defaults_equal_dataclass_defaults(step):
    make, classes = STEPS[step]
    args = make().parse_args(REQUIRED[step])
    for cls in classes:
        assert resolve(cls, args, {}) == cls(), cls.__name__


@pytest.mark.parametrize("step", sorted(STEPS))
def test_every_option_of_a_step_is_set_by_its_flag(step):
    make, classes = STEPS[step]
    argv = list(REQUIRED[step])
    for cls in classes:
        for f in options_of(cls):
            typed = TYPED[f.name][0]
            argv += [flag_of(f)] if typed is None else [flag_of(f), typed]
    args = make().parse_args(argv)
    for cls in classes:
        expected = {f.name: TYPED[f.name][1] for f in options_of(cls)}
        assert all(expected[f.name] != default_of(f) for f in options_of(cls))
        assert resolve(cls, args, {}) == cls(**expected), cls.__name__


@pytest.mark.parametrize("step", sorted(STEPS))
def test_the_help_of_every_step_shows_the_dataclass_defaults(step):
    text = subprocess.run([sys.executable, "-m", "dyngen.cli", step, "--help"], capture_output=True, text=True,
                          check=True).stdout
    text = re.sub(r"\s+", " ", text)
    for cls in STEPS[step][1]:
        for f in options_of(cls):
            default = default_of(f)
            assert flag_of(f) in text, f.name
            if default is not None and not isinstance(default, bool):
                shown = ", ".join(default) if isinstance(default, tuple) else str(default)
                assert re.search(re.escape(flag_of(f)) + r" .*?\(default: " + re.escape(shown) + r"\)", text), f.name


@pytest.mark.parametrize("step, option", [("identify", ["--order", "0"]), ("identify", ["--cutoff", "nan"]),
                                          ("identify", ["--smoothing", "0"]), ("identify", ["--kind", "all"]),
                                          ("identify", ["--candidates", "tilt,wobble"]),
                                          ("identify", ["--friction", "coulomb,stiction"]),
                                          ("diagnose", ["--min-gain", "2"]), ("diagnose", ["--sign-velocity", "0"]),
                                          ("excite", ["--margin", "0"]), ("excite", ["--iterations", "0"]),
                                          ("excite", ["--seed", "-1"])])
def test_the_steps_refuse_out_of_range_values(step, option, capsys):
    with pytest.raises(SystemExit):
        STEPS[step][0]().parse_args(REQUIRED[step] + option)
    assert f"argument {option[0]}" in capsys.readouterr().err.strip().splitlines()[-1]
