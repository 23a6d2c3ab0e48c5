"""The per-user cache of compiled programs and libraries, safe on a shared machine.

dyngen compiles the extractor driver and the model library once and reuses them. Their names
are predictable (hashes of deterministic sources), so a cache in a shared /tmp would let
another user plant a binary that the next dyngen run executes. Instead:

- the cache lives in the user's own cache directory (platformdirs: ~/.cache/dyngen on Linux;
  DYNGEN_CACHE_DIR overrides it), every folder of it created 0700;
- before anything in it is used, each folder is checked: a real directory (no symlink), owned
  by this user, not writable by anyone else; its ancestors owned by this user or root and,
  where others may write, sticky (as /tmp is). A folder that fails is refused, not repaired
  (except tightening the mode of our own folder);
- every artifact is written under a temporary name and renamed into place, with its SHA-256
  recorded beside it; `verified(path)` recomputes the hash before the artifact is run or
  loaded, so a file changed after it was built is rebuilt, never executed.
"""

from __future__ import annotations

import hashlib
import os
import stat
from pathlib import Path

from .errors import InputError

ENVIRONMENT = "DYNGEN_CACHE_DIR"


class CacheError(InputError):
    def __init__(self, folder: Path, message: str):
        super().__init__(str(folder), "", f"{message}; remove it, or set {ENVIRONMENT} to a private folder")


def root() -> Path:
    configured = os.environ.get(ENVIRONMENT)
    if configured:
        return Path(configured).absolute()
    import platformdirs

    return Path(platformdirs.user_cache_dir("dyngen", appauthor=False)).absolute()


def folder(kind: str, base: Path | None = None) -> Path:
    """The private cache folder `kind` (e.g. "drivers") under `base` (default: root()), created
    and checked."""
    base = Path(base).absolute() if base is not None else root()
    missing = [a for a in [base.parent, *base.parents] if not a.exists()]
    for ancestor in reversed(missing):  # e.g. ~/.cache on a fresh account
        try:
            ancestor.mkdir(mode=0o700, exist_ok=True)
        except OSError as err:
            raise CacheError(ancestor, f"cannot create the cache folder ({err.strerror or err})") from None
    _check_ancestors(base.parent)
    for path in (base, base / kind):
        try:
            path.mkdir(mode=0o700, exist_ok=True)
        except OSError as err:
            raise CacheError(path, f"cannot create the cache folder ({err.strerror or err})") from None
        _check_private(path)
    return base / kind


def _check_private(path: Path) -> None:
    info = os.lstat(path)
    if stat.S_ISLNK(info.st_mode) or not stat.S_ISDIR(info.st_mode):
        raise CacheError(path, "the cache folder is a symbolic link or not a folder")
    if info.st_uid != os.getuid():
        raise CacheError(path, f"the cache folder belongs to user id {info.st_uid}, not to you ({os.getuid()})")
    if info.st_mode & 0o077:
        os.chmod(path, 0o700)  # ours, merely too open (e.g. made under a loose umask): tighten it


def _check_ancestors(path: Path) -> None:
    for ancestor in [path, *path.parents]:
        try:
            info = os.stat(ancestor)
        except FileNotFoundError:
            continue  # created below with our own mode
        if info.st_uid not in (0, os.getuid()):
            raise CacheError(ancestor, f"a folder above the cache belongs to user id {info.st_uid}")
        if info.st_mode & 0o022 and not info.st_mode & stat.S_ISVTX:
            raise CacheError(ancestor, "a folder above the cache is writable by others and not sticky")


def digest_file(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _record(path: Path) -> Path:
    return path.with_name(path.name + ".sha256")


def install(built: Path, target: Path) -> Path:
    """Move a freshly built artifact into the cache and record its hash (both atomically)."""
    record = _record(target)
    tmp = record.with_name(record.name + f".{os.getpid()}.tmp")
    tmp.write_text(digest_file(built) + "\n")
    os.replace(built, target)
    os.replace(tmp, record)
    return target


def verified(target: Path) -> bool:
    """True when `target` exists and still has the hash recorded when it was built."""
    record = _record(target)
    try:
        info = os.lstat(target)
        expected = record.read_text().strip()
    except OSError:
        return False
    if not stat.S_ISREG(info.st_mode) or info.st_uid != os.getuid():
        return False
    return digest_file(target) == expected
