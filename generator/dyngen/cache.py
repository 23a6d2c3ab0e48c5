"""The per-user cache of compiled programs and libraries, safe on a shared machine.

dyngen compiles the extractor driver and the model library once and reuses them. Their names
are predictable (hashes of deterministic sources), so a cache in a shared /tmp would let
another user plant a binary that the next dyngen run executes. Instead:

- the cache lives in the user's own cache directory (platformdirs: ~/.cache/dyngen on Linux;
  DYNGEN_CACHE_DIR overrides it), every folder of it created 0700;
- before anything in it is used, each folder is checked: a real directory (no symlink), owned
  by this user; its ancestors owned by this user or root and, where others may write, sticky
  (as /tmp is). A folder that fails is refused, not repaired;
- tightening a folder does not bless what is in it: a cache folder found writable by group or
  others (anyone may have planted files there), or a cache root without the stamp this version
  writes (a cache an older dyngen merely tightened), has everything inside discarded, then is
  tightened to 0700 and rebuilt;
- every artifact is written under a temporary name and renamed into place, with its SHA-256
  recorded beside it (only into a folder that is private at that moment); `verified(path)`
  recomputes the hash before the artifact is run or loaded, so a file changed after it was
  built is rebuilt, never executed. A generated model folder in the cache is compared with
  the files dyngen would write, byte for byte, before it is compiled (`model_folder`).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import stat
from pathlib import Path

from .errors import InputError

ENVIRONMENT = "DYNGEN_CACHE_DIR"
# Written into the cache root by this version, only while the root is private: a root without it
# was made (or merely tightened) by an older dyngen, so its contents are discarded once.
STAMP = ".dyngen-cache-v2"


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
        _private_folder(path)
        if path == base:
            _stamp(base)
    return base / kind


def _private_folder(path: Path) -> None:
    try:
        path.mkdir(mode=0o700, exist_ok=True)
    except OSError as err:
        raise CacheError(path, f"cannot create the cache folder ({err.strerror or err})") from None
    _check_private(path)


def _check_private(path: Path) -> None:
    info = os.lstat(path)
    if stat.S_ISLNK(info.st_mode) or not stat.S_ISDIR(info.st_mode):
        raise CacheError(path, "the cache folder is a symbolic link or not a folder")
    if info.st_uid != os.getuid():
        raise CacheError(path, f"the cache folder belongs to user id {info.st_uid}, not to you ({os.getuid()})")
    if info.st_mode & 0o077:
        os.chmod(path, 0o700)  # first, so that nothing new is planted while we clean
        if info.st_mode & 0o022:  # others could write here: whatever is inside may be theirs
            _discard_contents(path)


def _stamp(base: Path) -> None:
    stamp = base / STAMP
    try:
        info = os.lstat(stamp)
        if stat.S_ISREG(info.st_mode) and info.st_uid == os.getuid():
            return
    except FileNotFoundError:
        pass
    _discard_contents(base)  # not made by this version while private: trust nothing in it
    stamp.write_text("dyngen cache: everything here was built by dyngen in this private folder\n")


def _discard_contents(path: Path) -> None:
    """Remove everything inside `path` (links are removed, never followed)."""
    for entry in os.scandir(path):
        try:
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(entry.path)
            else:
                os.unlink(entry.path)
        except FileNotFoundError:
            continue  # removed meanwhile (another dyngen run cleaning the same folder)
        except OSError as err:
            raise CacheError(Path(entry.path), "found in a cache folder others could write, and cannot be "
                             f"removed ({err.strerror or err})") from None


def _is_private(path: Path) -> bool:
    info = os.lstat(path)
    return stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid() and not info.st_mode & 0o022


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
    if not _is_private(target.parent):
        raise CacheError(target.parent, "the cache folder became writable by others while dyngen used it")
    tmp = record.with_name(record.name + f".{os.getpid()}.tmp")
    tmp.write_text(digest_file(built) + "\n")
    for path in (tmp, built):
        os.chmod(path, stat.S_IMODE(os.stat(path).st_mode) & 0o700)  # whatever the umask
    os.replace(built, target)
    os.replace(tmp, record)
    return target


def verified(target: Path) -> bool:
    """True when `target` exists and still has the hash recorded when it was built."""
    record = _record(target)
    try:
        if not _is_private(target.parent):
            return False
        for path in (target, record):
            info = os.lstat(path)
            if not stat.S_ISREG(info.st_mode) or info.st_uid != os.getuid() or info.st_mode & 0o022:
                return False
        expected = record.read_text().strip()
    except OSError:
        return False
    return digest_file(target) == expected


def model_folder(name: str, files: dict[str, str]) -> Path:
    """The generated folder `name` with exactly `files` (name -> text) in the private cache
    folder "models", keyed by their content. A folder already there is reused only when it
    holds exactly these files, byte for byte (regular files of ours, nothing else); anything
    else is discarded and written again, so the C compiled from it is the C dyngen generated."""
    from .atomic import write_folder

    digest = hashlib.sha256("".join(f"{k}\0{files[k]}\0" for k in sorted(files)).encode()).hexdigest()[:16]
    keyed = folder("models") / digest
    _private_folder(keyed)
    target = keyed / name
    if not _holds_exactly(target, files):
        write_folder(target, files)  # atomic: the folder is there whole or not at all
    return target


def _holds_exactly(path: Path, files: dict[str, str]) -> bool:
    try:
        info = os.lstat(path)
        if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid() or info.st_mode & 0o022:
            return False
        entries = {entry.name: entry for entry in os.scandir(path)}
        if set(entries) != set(files):
            return False
        for file_name, text in files.items():
            info = entries[file_name].stat(follow_symlinks=False)
            if not stat.S_ISREG(info.st_mode) or info.st_uid != os.getuid() or info.st_mode & 0o022:
                return False
            with open(path / file_name, "rb") as f:
                if f.read(len(text.encode()) + 1) != text.encode():
                    return False
    except OSError:
        return False
    return True
