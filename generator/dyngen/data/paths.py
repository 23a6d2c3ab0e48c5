"""Which files a `--data` value names: the file itself, or every file a glob matches.

A glob is expanded by dyngen (sorted, so that the order, and with it every result, does not
depend on the file system), so that it works quoted (`--data 'logs/*.csv'`), where a shell
would not expand it, and on a command line too long for thousands of names.
"""

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
