"""Which files a `--data` value names: the file, or every file a glob matches, expanded by dyngen
(sorted, so no result depends on the file system; works quoted and for thousands of names)."""

from __future__ import annotations

import glob

from ..errors import InputError, shorten

MAX_FILES = 100000


def expand(values) -> list[str]:
    out = []
    for value in values:
        if not glob.has_magic(value):
            out.append(value)
            continue
        found = sorted(glob.glob(value, recursive=True))
        if not found:
            raise InputError(shorten(value), "", "no file matches this pattern")
        out.extend(found)
        if len(out) > MAX_FILES:
            raise InputError(shorten(value), "", f"more than {MAX_FILES} recordings")
    return out
