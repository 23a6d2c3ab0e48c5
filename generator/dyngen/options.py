"""Step options: one dataclass per pipeline step is the only place its defaults live.

Each field is declared with `option(...)`: its default, its help text, its bounds or choices.
From the dataclass alone come the command-line flags (`add_arguments`), the checks of the
YAML block that may set the same options (`check_yaml`), and the resolved options
(`resolve`: the command line first, then the YAML block, then the dataclass default).
A flag not given leaves no attribute (argparse.SUPPRESS), so that "not given" differs from
a given value that is None (`--cutoff none`); its help shows the dataclass default.
Fields declared without `option(...)` are the step's own settings, not on the command line.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import MISSING, field, fields

from .arguments import real, whole
from .errors import shorten


def option(default, help: str, *, flag: str = "", metavar: str = "", choices: tuple = (),
           bounds: tuple | None = None, above: bool = False, repeat: bool = False, listed: bool = False,
           parse=None, const=None):
    """A dataclass field with what argparse and the YAML check need. flag: the command-line
    flag (default --name-with-dashes); bounds: (lowest, highest) for numbers, the lowest
    itself excluded with above; repeat: a tuple of strings given by repeating the flag (a YAML
    list); listed: a tuple of names given as one comma-separated argument (with choices: each
    one of them); parse: the
    argparse type of an option that is none of these (e.g. a number or a word). A bool
    default makes an on/off flag (a True default: give it flag="--no-..." to turn it off); const, a flag without argument that sets this value (for a
    default None meaning "decided from the data", e.g. --tilt)."""
    metadata = {"help": help, "flag": flag, "metavar": metavar, "choices": tuple(choices), "bounds": bounds,
                "above": above, "repeat": repeat, "listed": listed, "parse": parse, "const": const}
    if isinstance(default, (list, tuple)):
        return field(default_factory=lambda: tuple(default), metadata=metadata)
    return field(default=default, metadata=metadata)


def options_of(cls) -> list:
    """The fields of cls declared with option(...)."""
    return [f for f in fields(cls) if "help" in f.metadata]


def default_of(f):
    return f.default_factory() if f.default is MISSING else f.default


def flag_of(f) -> str:
    return f.metadata["flag"] or "--" + f.name.replace("_", "-")


def add_arguments(group, cls) -> None:
    """One flag per option of cls, absent from the parsed arguments unless given."""
    for f in options_of(cls):
        m, default = f.metadata, default_of(f)
        kwargs = {"dest": f.name, "default": argparse.SUPPRESS, "help": m["help"] + _shown(default)}
        if m["metavar"]:
            kwargs["metavar"] = m["metavar"]
        if m["const"] is not None:
            kwargs["action"], kwargs["const"] = "store_const", m["const"]
        elif isinstance(default, bool):  # a flag turns the default over (--x on, or --no-x off)
            kwargs["action"] = "store_false" if default else "store_true"
        elif m["repeat"]:
            kwargs["action"] = "append"
        elif m["choices"] and not m["listed"]:
            kwargs["choices"] = m["choices"]
        else:
            kwargs["type"] = _parser(f)
        group.add_argument(flag_of(f), **kwargs)


def _shown(default) -> str:
    """The help's note of the default: none for on/off flags and for None (the help says what
    happens then)."""
    if isinstance(default, bool) or default is None:
        return ""
    if isinstance(default, tuple):
        default = ", ".join(default)
    return f" (default: {default if default != '' else 'none'})"


def _parser(f):
    """The argparse type of an option: its own parse, a list of names, or arguments.whole or
    arguments.real over its bounds."""
    m = f.metadata
    if m["parse"]:
        return m["parse"]
    if m["listed"]:
        return _names_of(m["choices"]) if m["choices"] else names
    kind, bounds = type(default_of(f)), m["bounds"] or (-math.inf, math.inf)
    return whole(*bounds) if kind is int else real(*bounds, above=m["above"])


def names(text: str) -> tuple:
    """A comma-separated list of names, e.g. "coulomb, viscous" (empty entries left out)."""
    return tuple(x.strip() for x in text.split(",") if x.strip())


def _names_of(known: tuple):
    """names(), each one of `known` (an unknown one is refused with the flag named)."""
    def parse(text: str) -> tuple:
        given = names(text)
        unknown = [x for x in given if x not in known]
        if unknown:
            raise argparse.ArgumentTypeError(f"unknown name(s) {', '.join(unknown)}; expected some of "
                                             f"{', '.join(known)}")
        return given

    return parse


def _what(kind, bounds) -> str:
    what = "a whole number" if kind is int else "a number"
    return what if bounds is None else f"{what} from {bounds[0]:g} to {bounds[1]:g}"


def _out_of_bounds(value, bounds, above: bool = False) -> str:
    if isinstance(value, float) and not math.isfinite(value):
        return f"expected a finite number, got {value!r}"
    if bounds is None:
        return ""
    low_ok = value > bounds[0] if above else value >= bounds[0]
    if not low_ok or value > bounds[1]:
        span = f"above {bounds[0]:g} and at most" if above else f"from {bounds[0]:g} to"
        return f"expected a value {span} {bounds[1]:g}, got {value:g}"
    return ""


def yaml_keys(cls) -> set:
    return {f.name for f in options_of(cls)}


def check_yaml(cls, block: dict, fail, prefix: str) -> dict:
    """The YAML block's options of cls, checked: fail(field, message) on a wrong type, value or
    choice. Keys that are not options of cls, and repeated (free-text) options, whose grammar
    only the caller knows (e.g. identities), are left to the caller."""
    out = {}
    for f in options_of(cls):
        if f.name not in block:
            continue
        value, m, kind = block[f.name], f.metadata, type(default_of(f))
        where = f"{prefix}.{f.name}"
        if m["repeat"]:
            continue
        if m["parse"]:  # the command line's own parser, on the YAML's text of the value
            try:
                value = m["parse"](str(value))
            except argparse.ArgumentTypeError as err:
                fail(where, str(err))
        elif m["listed"]:
            if not (isinstance(value, list) and all(isinstance(x, str) for x in value)):
                fail(where, f"expected a list of names, got {shorten(repr(value), 40)}")
            unknown = [x for x in value if m["choices"] and x not in m["choices"]]
            if unknown:
                fail(where, f"unknown name(s) {shorten(', '.join(unknown), 40)}; expected some of "
                     f"{', '.join(m['choices'])}")
            value = tuple(value)
        elif m["choices"]:
            if value not in m["choices"]:
                fail(where, "expected " + " or ".join(f'"{c}"' for c in m["choices"]) + f", got {shorten(repr(value), 40)}")
        elif kind is bool:
            if not isinstance(value, bool):
                fail(where, f"expected true or false, got {shorten(repr(value), 40)}")
        elif isinstance(value, bool) or not isinstance(value, (int, float) if kind is float else kind):
            fail(where, f"expected {_what(kind, m['bounds'])}, got {shorten(repr(value), 40)}")
        else:
            problem = _out_of_bounds(value, m["bounds"], m["above"])
            if problem:
                fail(where, problem)
            value = kind(value)
        out[f.name] = value
    return out


def resolve(cls, args, block: dict, **given):
    """Options of cls: each from the command line when given there, else from the (checked)
    YAML block, else the dataclass default. given: the step's own settings (fields without
    option(...)) or values the caller read itself (e.g. a file the command line names)."""
    values = {}
    for f in options_of(cls):
        if args is not None and hasattr(args, f.name):
            value = getattr(args, f.name)
        elif f.name in block:
            value = block[f.name]
        else:
            continue
        values[f.name] = tuple(value) if f.metadata["repeat"] else value
    return cls(**values, **given)
