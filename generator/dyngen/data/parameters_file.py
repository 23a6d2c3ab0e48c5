"""Link parameters from a YAML file: the extraction output (`links:`), a solution file
(`solution:`, e.g. examples/lwr_paper_solution.yaml) or a robot description
(`parameters.nominal`). Each link is {m, c: [3], I: [6]} (docs/conventions.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from ..errors import InputError


def read_link_parameters(path, dof: int) -> np.ndarray:
    path = Path(path)
    name = path.name
    try:
        doc = yaml.safe_load(path.read_text())
    except OSError as err:
        raise InputError(str(path), "", f"cannot read the file ({err.strerror})") from None
    except yaml.YAMLError as err:
        raise InputError(name, "", f"malformed YAML: {getattr(err, 'problem', err)}") from None
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
            row = [float(link["m"]), *map(float, link["c"]), *map(float, link["I"])]
        except (KeyError, TypeError, ValueError):
            raise InputError(name, where, "expected {m: number, c: [3 numbers], I: [6 numbers]}") from None
        if len(row) != 10 or not np.all(np.isfinite(row)):
            raise InputError(name, where, "expected {m: number, c: [3 numbers], I: [6 numbers]}, all finite")
        values += row
    return np.array(values)
