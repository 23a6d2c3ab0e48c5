"""Step options: one dataclass per pipeline step is the only place its defaults live.

Each field is declared with `option(...)`: its default, its help text, its bounds or choices.
From the dataclass alone come the command-line flags (`add_arguments`), the checks of the
YAML block that may set the same options (`check_yaml`), and the resolved options
(`resolve`: the command line first, then the YAML block, then the dataclass default).
Flags default to None so that "not given" is visible; their help shows the dataclass default.
"""

from __future__ import annotations

import math
from dataclasses import MISSING, field, fields

from .arguments import real, whole
from .errors import shorten


def option(default, help: str, *, flag: str = "", metavar: str = "", choices: tuple = (),
           bounds: tuple | None = None, repeat: bool = False):
    """A dataclass field with what argparse and the YAML check need. flag: the command-line
    flag (default --name-with-dashes); bounds: (lowest, highest) for numbers; repeat: a tuple
    of strings given by repeating the flag (a YAML list)."""
    metadata = {"help": help, "flag": flag, "metavar": metavar, "choices": tuple(choices), "bounds": bounds,
                "repeat": repeat}
    if repeat:
        return field(default_factory=lambda: tuple(default), metadata=metadata)
    return field(default=default, metadata=metadata)


def default_of(f):
    return f.default_factory() if f.default is MISSING else f.default


def flag_of(f) -> str:
    return f.metadata["flag"] or "--" + f.name.replace("_", "-")


def add_arguments(group, cls) -> None:
    """One flag per option of cls, each defaulting to None (resolve fills in the rest)."""
    for f in fields(cls):
        m, default = f.metadata, default_of(f)
        shown = ", ".join(default) if m["repeat"] else default
        kwargs = {"dest": f.name, "default": None, "help": f"{m['help']} (default: {shown if shown != '' else 'none'})"}
        if m["metavar"]:
            kwargs["metavar"] = m["metavar"]
        if m["repeat"]:
            kwargs["action"] = "append"
        elif m["choices"]:
            kwargs["choices"] = m["choices"]
        else:
            kwargs["type"] = _parser(f)
        group.add_argument(flag_of(f), **kwargs)


def _parser(f):
    """The argparse type of a number option: arguments.whole or arguments.real over its bounds."""
    kind, bounds = type(default_of(f)), f.metadata["bounds"] or (-math.inf, math.inf)
    return whole(*bounds) if kind is int else real(*bounds)


def _what(kind, bounds) -> str:
    what = "a whole number" if kind is int else "a number"
    return what if bounds is None else f"{what} from {bounds[0]:g} to {bounds[1]:g}"


def _out_of_bounds(value, bounds) -> str:
    if isinstance(value, float) and not math.isfinite(value):
        return f"expected a finite number, got {value!r}"
    if bounds is not None and not bounds[0] <= value <= bounds[1]:
        return f"expected a value from {bounds[0]:g} to {bounds[1]:g}, got {value:g}"
    return ""


def yaml_keys(cls) -> set:
    return {f.name for f in fields(cls)}


def check_yaml(cls, block: dict, fail, prefix: str) -> dict:
    """The YAML block's options of cls, checked: fail(field, message) on a wrong type, value or
    choice. Keys that are not options of cls, and repeated (free-text) options, whose grammar
    only the caller knows (e.g. identities), are left to the caller."""
    out = {}
    for f in fields(cls):
        if f.name not in block:
            continue
        value, m, kind = block[f.name], f.metadata, type(default_of(f))
        where = f"{prefix}.{f.name}"
        if m["repeat"]:
            continue
        if m["choices"]:
            if value not in m["choices"]:
                fail(where, "expected " + " or ".join(f'"{c}"' for c in m["choices"]) + f", got {shorten(repr(value), 40)}")
        elif isinstance(value, bool) or not isinstance(value, (int, float) if kind is float else kind):
            fail(where, f"expected {_what(kind, m['bounds'])}, got {shorten(repr(value), 40)}")
        else:
            problem = _out_of_bounds(value, m["bounds"])
            if problem:
                fail(where, problem)
            value = kind(value)
        out[f.name] = value
    return out


def resolve(cls, args, block: dict):
    """Options of cls: each from the command line when given there, else from the (checked)
    YAML block, else the dataclass default."""
    values = {}
    for f in fields(cls):
        value = getattr(args, f.name, None) if args is not None else None
        if value is None:
            value = block.get(f.name)
        if value is not None:
            values[f.name] = tuple(value) if f.metadata["repeat"] else value
    return cls(**values)
