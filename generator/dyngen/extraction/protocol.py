"""The problem file the extractor driver reads, written down once.

One line per field, `key value...`, in the order of SCHEMA. The Python writer (`problem_text`)
and reader (`read_problem_text`) below and the C++ reader, writer and the members of the
driver's Problem (generator/dyngen/extraction/driver_cpp/protocol.hpp, rendered from SCHEMA by `cpp_header`
through templates/protocol.hpp.j2) all follow it, so an option is added by one line here (and
its field in description/extraction_options.py), then `python3 -m dyngen.extraction.protocol`.

The result file the driver writes back follows RESULT the same way: the C++ Result, its writer
and reader (`--echo-result`) are rendered into protocol.hpp, the Python reader
(`read_result_text`, used by extraction/driver.py) and writer (`result_text`) read RESULT.

Kinds (C++ type, and the text after the key):
  integer   int, or the field's `cpp` type     one whole number
  real      double                             one number (shortest round-trip text)
  word      std::string                        one word
  reals     Eigen::VectorXd                    `length` numbers (length: parameters)
  flags     std::vector<int> of the set ones   `length` 0/1 values
  blocks    std::vector<Block>                 count, then per block: kind rows, W row by row, v
  terms     std::vector<std::vector<Term>>     count, then per polynomial: terms, (c, factors, indices)...
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

MAGIC, VERSION = "dyngen-extraction", 3


@dataclass(frozen=True)
class Field:
    key: str  # in the file, and the C++ Problem member
    kind: str
    value: Callable  # (problem, stage, options) -> the value written
    cpp: str = ""  # the C++ member type, when it is not the kind's
    length: str = ""  # "parameters" for reals and flags

    @property
    def cpp_type(self) -> str:
        return self.cpp or {"integer": "int", "real": "double", "word": "std::string", "reals": "Eigen::VectorXd",
                            "flags": "std::vector<int>", "blocks": "std::vector<Block>",
                            "terms": "std::vector<std::vector<Term>>"}[self.kind]


def _opt(name, kind, cpp=""):
    """An extraction option (description/extraction_options.py) the driver reads."""
    return Field(name, kind, lambda problem, stage, options: getattr(options, name), cpp)


SCHEMA = (
    Field("lower", "reals", lambda problem, stage, options: problem.lower, length="parameters"),
    Field("upper", "reals", lambda problem, stage, options: problem.upper, length="parameters"),
    Field("value", "reals", lambda problem, stage, options: stage.value, length="parameters"),
    Field("reference", "reals", lambda problem, stage, options: problem.reference, length="parameters"),
    Field("weight", "reals", lambda problem, stage, options: problem.weight, length="parameters"),
    Field("center", "reals", lambda problem, stage, options: problem.center, length="parameters"),
    Field("free", "flags", lambda problem, stage, options: stage.free, length="parameters"),
    Field("has_total_mass", "integer", lambda problem, stage, options: int(problem.total_mass is not None), "bool"),
    Field("mass_lo", "real", lambda problem, stage, options: (problem.total_mass or (0.0, 0.0))[0]),
    Field("mass_hi", "real", lambda problem, stage, options: (problem.total_mass or (0.0, 0.0))[1]),
    Field("blocks", "blocks", lambda problem, stage, options: stage.blocks),
    Field("next_blocks", "blocks", lambda problem, stage, options: stage.next_blocks),
    Field("nearest", "integer", lambda problem, stage, options: int(getattr(stage, "nearest", True)), "bool"),
    Field("equalities", "terms", lambda problem, stage, options: problem.equalities),
    _opt("margin", "real"),
    _opt("restarts", "integer"),
    _opt("seed", "integer", "unsigned long"),
    _opt("threads", "integer"),
    _opt("global_algorithm", "word"),
    _opt("global_maxeval", "integer"),
    _opt("local_maxeval", "integer"),
    _opt("tolerance", "real"),
    _opt("hops", "integer"),
    _opt("hop_size", "real"),
)


def _number(x) -> str:
    return repr(float(x))


def _format(field: Field, value) -> list[str]:
    """The lines of one field."""
    kind = field.kind
    if kind == "integer":
        return [f"{field.key} {int(value)}"]
    if kind == "real":
        return [f"{field.key} {_number(value)}"]
    if kind == "word":
        return [f"{field.key} {value}"]
    if kind == "reals":
        return [f"{field.key} " + " ".join(_number(v) for v in value)]
    if kind == "flags":
        return [f"{field.key} " + " ".join(str(int(bool(f))) for f in value)]
    if kind == "blocks":
        lines = [f"{field.key} {len(value)}"]
        for block in value:
            lines.append(f"{block.kind} {block.W.shape[0]}")
            lines.extend(" ".join(_number(v) for v in row) for row in block.W)
            lines.append(" ".join(_number(v) for v in block.v))
        return lines
    if kind == "terms":
        lines = [f"{field.key} {len(value)}"]
        for terms in value:
            lines.append(str(len(terms)) + " " + " ".join(
                f"{_number(c)} {len(idx)} " + " ".join(map(str, idx)) for c, idx in terms))
        return lines
    raise ValueError(kind)


def problem_text(problem, stage, options) -> str:
    lines = [f"{MAGIC} {VERSION}", f"parameters {problem.lower.size}"]
    for field in SCHEMA:
        lines += _format(field, field.value(problem, stage, options))
    return "\n".join(lines + ["end"]) + "\n"


@dataclass
class ReadBlock:
    kind: str
    W: np.ndarray
    v: np.ndarray


def read_problem_text(text: str, ranks: dict) -> dict:
    """The fields of a problem file (as the driver echoes it): key -> value; ranks: coefficient
    kind -> number of base coefficients (the columns of a block's W)."""
    words = iter(text.split())

    def expect(word):
        got = next(words)
        if got != word:
            raise ValueError(f"expected {word!r}, got {got!r}")

    expect(MAGIC)
    expect(str(VERSION))
    expect("parameters")
    n = int(next(words))
    out = {}
    for field in SCHEMA:
        expect(field.key)
        kind = field.kind
        if kind == "integer":
            out[field.key] = int(next(words))
        elif kind == "real":
            out[field.key] = float(next(words))
        elif kind == "word":
            out[field.key] = next(words)
        elif kind == "reals":
            out[field.key] = np.array([float(next(words)) for _ in range(n)])
        elif kind == "flags":
            out[field.key] = np.array([int(next(words)) for _ in range(n)], dtype=bool)
        elif kind == "blocks":
            blocks = []
            for _ in range(int(next(words))):
                name, rows = next(words), int(next(words))
                W = np.array([float(next(words)) for _ in range(rows * ranks[name])]).reshape(rows, ranks[name])
                blocks.append(ReadBlock(name, W, np.array([float(next(words)) for _ in range(rows)])))
            out[field.key] = blocks
        elif kind == "terms":
            polys = []
            for _ in range(int(next(words))):
                terms = []
                for _ in range(int(next(words))):
                    c = float(next(words))
                    terms.append((c, [int(next(words)) for _ in range(int(next(words)))]))
                polys.append(terms)
            out[field.key] = polys
    expect("end")
    return out


@dataclass(frozen=True)
class ResultField:
    """One field of the result file, `key value...` in the order of RESULT."""

    key: str  # in the file, and the C++ Result member
    kind: str  # integer, real, word, reals, or residuals (count, then per block: kind rows values)
    length: str = ""  # reals: "parameters", "links", or the key of an earlier integer field
    ok_only: bool = False  # written only when status is "ok"

    @property
    def cpp_type(self) -> str:
        return {"integer": "int", "real": "double", "word": "std::string", "reals": "Eigen::VectorXd",
                "residuals": "std::vector<Residual>"}[self.kind]

    @property
    def cpp_read(self) -> str:
        """The C++ expression that reads the value (Reader r, the Result so far R)."""
        size = {"parameters": "kParameters", "links": "kLinks"}.get(self.length, f"R.{self.length}")
        return {"integer": "static_cast<int>(r.integer())", "real": "r.number()", "word": "r.word()",
                "reals": f"r.vector({size})", "residuals": "read_residuals(r)"}[self.kind]


RESULT_MAGIC = "dyngen-extraction-result"

RESULT = (
    ResultField("restarts", "integer"),
    ResultField("consistent", "integer"),  # restarts that end physically consistent
    ResultField("restart_costs", "reals", "restarts"),
    ResultField("restart_violations", "reals", "restarts"),
    ResultField("status", "word"),  # ok | infeasible
    ResultField("best_restart", "integer", ok_only=True),
    ResultField("fit_cost", "real", ok_only=True),  # the best restart's cost
    ResultField("cost", "real", ok_only=True),  # the chosen parameters' cost
    ResultField("violation", "real", ok_only=True),
    ResultField("parameters", "reals", "parameters"),  # infeasible: the least violating restart's
    ResultField("residuals", "residuals", ok_only=True),  # per block: W pi(p) - v
    ResultField("lambda_min", "reals", "links", ok_only=True),
)


def result_text(values: dict, links: int) -> str:
    """A result file (as the driver writes it) from key -> value; residuals: kind -> vector."""
    lines = [f"{RESULT_MAGIC} {VERSION}", f"links {links}"]
    for field in RESULT:
        if field.ok_only and values["status"] != "ok":
            continue
        value = values[field.key]
        if field.kind == "residuals":
            lines.append(f"{field.key} {len(value)}")
            lines.extend(f"{kind} {len(r)} " + " ".join(_number(x) for x in r) for kind, r in value.items())
        else:
            lines += _format(Field(field.key, field.kind, None), value)
    return "\n".join(lines + ["end"]) + "\n"


def read_result_text(text: str) -> dict:
    """The fields of a result file: key -> value (residuals: kind -> vector); the ok-only fields
    are absent when the status is not "ok"."""
    words = iter(text.split())

    def expect(word):
        got = next(words)
        if got != word:
            raise ValueError(f"result file: expected {word!r}, got {got!r}")

    def reals(count):
        return np.array([float(next(words)) for _ in range(count)])

    expect(RESULT_MAGIC)
    expect(str(VERSION))
    expect("links")
    links = int(next(words))
    out = {}
    for field in RESULT:
        if field.ok_only and out["status"] != "ok":
            continue
        expect(field.key)
        if field.kind == "integer":
            out[field.key] = int(next(words))
        elif field.kind == "real":
            out[field.key] = float(next(words))
        elif field.kind == "word":
            out[field.key] = next(words)
        elif field.kind == "reals":
            sizes = {"parameters": 10 * links, "links": links}
            out[field.key] = reals(sizes[field.length] if field.length in sizes else out[field.length])
        elif field.kind == "residuals":
            residuals = {}
            for _ in range(int(next(words))):
                kind = next(words)
                residuals[kind] = reals(int(next(words)))
            out[field.key] = residuals
    expect("end")
    return out


def cpp_header() -> str:
    """protocol.hpp of the static driver (generator/dyngen/extraction/driver_cpp/), rendered from SCHEMA."""
    from ..emission.render import environment

    return environment().get_template("protocol.hpp.j2").render(
        protocol=[{"key": f.key, "kind": f.kind, "cpp_type": f.cpp_type} for f in SCHEMA],
        result=[{"key": f.key, "cpp_type": f.cpp_type, "read": f.cpp_read, "ok_only": f.ok_only} for f in RESULT],
        protocol_magic=MAGIC, result_magic=RESULT_MAGIC, protocol_version=VERSION)


HEADER = Path(__file__).resolve().parent / "driver_cpp" / "protocol.hpp"

if __name__ == "__main__":  # rewrite the checked-in header after a schema change
    HEADER.write_text(cpp_header())
