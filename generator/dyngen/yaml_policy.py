"""One policy for every YAML scalar and node dyngen reads (used by untrusted.read_yaml).

PyYAML's SafeLoader follows YAML 1.1 and turns plain text into Python objects a robot file
never means: `2026-01-01` becomes a date, `1:30` the number 90, `010` the number 8, `yes` and
`on` True, and a 5000-digit integer either a huge number or a ValueError. The loader below
resolves plain scalars by YAML 1.2's core schema, restricted further:

- null: `~`, `null` (any case as YAML 1.2 spells it) or nothing; bool: `true`, `false`;
- integers: decimal digits with an optional sign, read in base 10 (`010` is ten), at most
  MAX_INT_DIGITS digits;
- floats: decimal with a point and/or an exponent (`1e-3`), `.inf`, `.nan`;
- anything else (dates, `1:30`, `0x1F`, `1_000`, `yes`) is a string, which a number field
  then refuses with its name.

Explicit tags are limited to `!!str`, `!!int`, `!!float`, `!!bool`, `!!null`, `!!map` and
`!!seq`, and a tagged value must read as its tag says (`!!float abc` is refused, naming the
field). Aliases are refused (the "billion laughs"), duplicate keys too (the last would win
silently), and composing stops after MAX_NODES nodes (a 4 MB list took 73 s): a description
of 40 joints with bounds and identified coefficients has a few thousand.
"""

from __future__ import annotations

import re

import yaml

from .errors import InputError, shorten

MAX_NODES = 20_000
MAX_INT_DIGITS = 20  # a seed or a count; no robot quantity needs more

STR, INT, FLOAT, BOOL, NULL = (f"tag:yaml.org,2002:{t}" for t in ("str", "int", "float", "bool", "null"))
MAP, SEQ = "tag:yaml.org,2002:map", "tag:yaml.org,2002:seq"
_INT = re.compile(r"[-+]?[0-9]+", re.ASCII)
_FLOAT = re.compile(r"[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?|[-+]?\.(inf|Inf|INF)|\.(nan|NaN|NAN)",
                    re.ASCII)
_BOOL = re.compile(r"true|True|TRUE|false|False|FALSE")
_NULL = re.compile(r"~|null|Null|NULL|")


class PolicyError(yaml.YAMLError):
    def __init__(self, field: str, mark, message: str):
        super().__init__(message)
        self.field, self.message = f"{field} (line {mark.line + 1})", message


class Loader(yaml.SafeLoader):
    """SafeLoader with the core-schema resolvers above, no aliases, no duplicate keys, a node
    budget, and the path of every node kept for messages (joints[3].a)."""

    yaml_implicit_resolvers: dict = {}  # own table, filled below; YAML 1.1's is not inherited

    def __init__(self, stream):
        super().__init__(stream)
        self.nodes = 0
        self.path: list[str] = []

    def field(self) -> str:
        return "".join(self.path).lstrip(".") or "(top level)"

    def compose_node(self, parent, index):
        if isinstance(parent, yaml.SequenceNode):
            self.path.append(f"[{index}]")
        elif isinstance(parent, yaml.MappingNode) and isinstance(index, yaml.ScalarNode):
            self.path.append(f".{shorten(index.value, 40)}")
        else:
            self.path.append("")
        try:
            if self.check_event(yaml.AliasEvent):
                raise PolicyError(self.field(), self.peek_event().start_mark, "aliases (*name) are not allowed")
            self.nodes += 1
            if self.nodes > MAX_NODES:
                raise PolicyError(self.field(), self.peek_event().start_mark,
                                  f"more than {MAX_NODES} values in the file (a description has a few thousand)")
            node = super().compose_node(parent, index)
            if isinstance(node, yaml.ScalarNode):
                _check_scalar(node, self.field())
            elif node.tag not in (MAP, SEQ):
                raise PolicyError(self.field(), node.start_mark, f"the tag {_short(node.tag)} is not allowed "
                                  "(plain data only)")
        finally:
            self.path.pop()
        return node

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                duplicate = key in seen
            except TypeError:  # an unhashable key: the base class reports it
                break
            if duplicate:
                raise yaml.constructor.ConstructorError(None, None, f"duplicate key {shorten(key)!s}",
                                                        key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_int(self, node):
        return int(node.value, 10)  # never octal, hex or base 60: _check_scalar allowed digits only

    def construct_yaml_float(self, node):
        text = node.value.lower()
        return float(text.replace(".inf", "inf").replace(".nan", "nan"))

    def construct_yaml_bool(self, node):
        return node.value.lower() == "true"


def _short(tag: str) -> str:
    return shorten(tag.replace("tag:yaml.org,2002:", "!!"))


def _check_scalar(node, field: str) -> None:
    """An implicit tag is one of the core schema's; an explicit one must fit its value."""
    text = node.value
    rules = {INT: _INT, FLOAT: _FLOAT, BOOL: _BOOL, NULL: _NULL}
    if node.tag == STR:
        return
    if node.tag not in rules:
        raise PolicyError(field, node.start_mark, f"the tag {_short(node.tag)} is not allowed (plain data only)")
    if node.tag == FLOAT and _INT.fullmatch(text):
        pass  # !!float 3 is 3.0
    elif not rules[node.tag].fullmatch(text):
        raise PolicyError(field, node.start_mark, f'"{shorten(text)}" is not {node.tag.rsplit(":", 1)[1]} (tagged !!'
                          f'{node.tag.rsplit(":", 1)[1]})')
    if node.tag == INT and len(text.lstrip("+-")) > MAX_INT_DIGITS:
        raise PolicyError(field, node.start_mark, f"an integer of {len(text.lstrip('+-'))} digits (at most {MAX_INT_DIGITS}): "
                          "value out of range")


Loader.add_implicit_resolver(BOOL, re.compile(rf"^(?:{_BOOL.pattern})$"), list("tTfF"))
Loader.add_implicit_resolver(INT, re.compile(rf"^(?:{_INT.pattern})$", re.ASCII), list("-+0123456789"))
Loader.add_implicit_resolver(FLOAT, re.compile(rf"^(?:{_FLOAT.pattern})$", re.ASCII), list("-+0123456789."))
Loader.add_implicit_resolver(NULL, re.compile(rf"^(?:{_NULL.pattern})$"), ["~", "n", "N", ""])
for _tag in (INT, FLOAT, BOOL):
    Loader.add_constructor(_tag, getattr(Loader, f"construct_yaml_{_tag.rsplit(':', 1)[1]}"))


def load(text: str, name: str):
    """Plain data from YAML text; every problem an InputError naming `name` and the field or line."""
    loader = None
    try:
        loader = Loader(text)  # the reader refuses control characters here already
        return loader.get_single_data()
    except PolicyError as err:
        raise InputError(name, err.field, err.message) from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None) or getattr(err, "context_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        if isinstance(err, yaml.reader.ReaderError):
            line = text[:err.position].count("\n") + 1
            where = f"line {line}, column {err.position - text.rfind(chr(10), 0, err.position)}"
            err.problem = f"character U+{err.character:04X} is not allowed in YAML"
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        if "could not determine a constructor" in problem:
            problem = "tags such as !!python/... are not allowed (plain data only)"
        raise InputError(name, where, f"malformed YAML: {shorten(problem)}") from None
    except RecursionError:
        raise InputError(name, "", "malformed YAML: nested too deeply") from None
    finally:
        if loader is not None:
            loader.dispose()
