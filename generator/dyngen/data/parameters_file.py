"""Link parameters from a YAML file: the extraction output (`links:`), a solution file
(`solution:`, e.g. examples/lwr_paper_solution.yaml) or a robot description
(`parameters.nominal`). Each link is {m, c: [3], I: [6]} (docs/conventions.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError
from ..untrusted import read_yaml


def read_link_parameters(path, dof: int) -> np.ndarray:
    path = Path(path)
    name = path.name
    doc = read_yaml(path)  # plain data only; duplicate keys, aliases, bad encodings refused
    if not isinstance(doc, dict):
        raise InputError(name, "", "expected a mapping with `links:`, `solution:` or `parameters.nominal`")
    for key in ("links", "solution"):
        if key in doc:
            field, links = key, doc[key]
            break
    else:
        nominal = (doc.get("parameters") or {}).get("nominal") if isinstance(doc.get("parameters"), dict) else None
        if nominal is None:
            raise InputError(name, "", "no link parameters: expected `links:`, `solution:` or `parameters.nominal`")
        field, links = "parameters.nominal", nominal
    if not isinstance(links, list) or len(links) != dof:
        got = len(links) if isinstance(links, list) else type(links).__name__
        raise InputError(name, field, f"expected {dof} links (one per joint), got {got}")
    values = []
    for i, link in enumerate(links):
        where = f"{field}[{i}]"
        try:
            if not isinstance(link, dict) or not all(isinstance(link[k], list) for k in ("c", "I")):
                raise TypeError
            row = [_number(link["m"]), *map(_number, link["c"]), *map(_number, link["I"])]
        except (KeyError, TypeError, ValueError):
            raise InputError(name, where, "expected {m: number, c: [3 numbers], I: [6 numbers]}") from None
        if len(row) != 10 or not np.all(np.isfinite(row)) or np.abs(row).max() > 1e5:
            raise InputError(name, where, "expected {m: number, c: [3 numbers], I: [6 numbers]}, all finite "
                             "and at most 1e5 in size")
        if row[0] <= 0:
            raise InputError(name, f"{where}.m", f"expected a positive mass, got {row[0]:g}")
        values += row
    return np.array(values)


def _number(value) -> float:
    """A YAML number; strings ("1e3", "nan") are not numbers here."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError
    return float(value)


def prior_or_nominal(prior, robot):
    """The link parameters a recording is judged against (data/trust.py): `prior` where given, else the
    robot's parameters.nominal, else None."""
    if prior is not None:
        return np.asarray(prior, dtype=float)
    return None if robot.nominal is None else np.array([v for link in robot.nominal for v in link.as_tuple()])
