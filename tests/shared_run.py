"""What the xdist workers of one test run build once and share: derived arms and compiled libraries.

Deriving an arm takes 5-10 s and compiling its C 10-20 s, and every worker used to repeat both for
every arm it met. Now the first worker that needs a result makes it under a lock, in the run's own
folder (pytest's basetemp: per user, per run, private, discarded with the run), and the others read it.
Keys are content hashes of what decides the result, so a changed input is never served stale.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import pickle
from contextlib import contextmanager
from pathlib import Path

_FOLDER: Path | None = None


def use(folder: Path) -> None:
    """Called once per worker by conftest with the folder all workers of this run share."""
    global _FOLDER
    _FOLDER = Path(folder)
    _FOLDER.mkdir(mode=0o700, exist_ok=True)


def folder(kind: str) -> Path | None:
    """The shared folder `kind`, or None outside a test run (callers then use their own)."""
    if _FOLDER is None:
        return None
    path = _FOLDER / kind
    path.mkdir(mode=0o700, exist_ok=True)
    return path


def digest(*parts) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(part if isinstance(part, bytes) else repr(part).encode())
        h.update(b"\0")
    return h.hexdigest()[:20]


@contextmanager
def locked(name: str):
    """One worker at a time for `name` (an flock on a file in the shared folder)."""
    if _FOLDER is None:
        yield
        return
    with open(_FOLDER / f"{name}.lock", "w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def once(kind: str, key: str, make):
    """make()'s result, made by the first worker to ask and pickled for the others. Only this run's
    own workers write the folder, so reading the pickle back is reading our own output."""
    where = folder(kind)
    if where is None:
        return make()
    path = where / f"{key}.pickle"
    with locked(f"{kind}-{key}"):
        if path.exists():
            return pickle.loads(path.read_bytes())
        value = make()
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_bytes(pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL))
        tmp.rename(path)
        return value
