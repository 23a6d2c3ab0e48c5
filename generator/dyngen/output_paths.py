"""One policy for every path a command writes (generate -o, extract --out, identify -o,
diagnose --out, excite -o), checked before any work is done. docs/untrusted-input.md states it:

- the path is made absolute; a symbolic link on the way that another user made, or that is
  not the user's and sits in a folder others may write (planted in /tmp or a shared folder),
  is refused; the user's own links are followed (they named them);
- a results folder (DIR/<robot>/ of generate and extract, diagnose's folder) is replaced as a
  whole, never written through: if it is a symbolic link or a file it is refused; if it holds
  anything and is not marked as written by dyngen (the MARKER file, or a generated model's
  manifest.json), it is refused unless --force, so the user's own files are never deleted
  silently; what is replaced is said;
- a file output (identify -o, excite -o) that is a folder is refused; an existing file is
  replaced (and said so at the end) by renaming a new file over it, so a link there is replaced, not
  followed;
- nothing is written over one of the command's own inputs, or over a folder holding one.

results_folder() then writes a folder as one unit: into a sibling temporary folder, renamed
into place at the end, so an interrupted run leaves the old folder or the complete new one.
"""

from __future__ import annotations

import json
import os
import stat
from contextlib import contextmanager
from pathlib import Path

from .atomic import staged_folder
from .errors import InputError

MARKER = ".dyngen-output"
# What this run will replace, said once it has succeeded (cli.main): a note printed before the
# work would stand beside an error line if the run then failed.
REPLACED: list[str] = []
_MARKER_TEXT = "This folder was written by dyngen as a whole; the next run replaces it.\n"


def _fail(path: Path, message: str):
    raise InputError(str(path), "", message)


def _absolute(path) -> Path:
    return Path(os.path.abspath(os.fspath(path)))


def _check_links(path: Path) -> None:
    """Refuse a link on the way to `path` that someone else made: another user's link (it
    points wherever they choose), or any link not ours in a folder others can write (planted
    in /tmp or a shared folder). The user's own links, and root's, are followed."""
    for ancestor in reversed([path, *path.parents]):
        try:
            info = os.lstat(ancestor)
        except (FileNotFoundError, NotADirectoryError):
            return  # the rest is created (or refused as "not a folder" by the caller)
        except OSError as err:
            _fail(ancestor, f"cannot be checked ({err.strerror or err})")
        if stat.S_ISLNK(info.st_mode) and info.st_uid != os.getuid():
            shared = os.stat(ancestor.parent).st_mode & 0o022
            if info.st_uid != 0 or shared:
                _fail(ancestor, f"a symbolic link made by user id {info.st_uid}"
                      + (" in a folder others can write" if shared else "")
                      + "; dyngen does not follow links others made (name the real folder)")


def _check_inputs(target: Path, inputs, folder: bool) -> None:
    real = Path(os.path.realpath(target))
    for given in inputs:
        if not given:
            continue
        source = Path(os.path.realpath(os.fspath(given)))
        if source == real or (folder and real in source.parents):
            _fail(target, f"would overwrite the command's own input {given}; choose another output")


def _made_by_dyngen(folder: Path) -> bool:
    if (folder / MARKER).is_file():
        return True
    try:
        return json.loads((folder / "manifest.json").read_text())["generator"].startswith("dyngen")
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return False


def check_folder(target, inputs=(), force: bool = False) -> str | None:
    """Check the results folder `target` before any work; returns a note of what it will
    replace, or None. InputError when the policy refuses it."""
    target = _absolute(target)
    _check_links(target)
    for ancestor in target.parents:
        if ancestor.exists() or ancestor.is_symlink():
            if not ancestor.is_dir():
                _fail(ancestor, "exists and is not a folder")
            break
    _check_inputs(target, inputs, folder=True)
    try:
        info = os.lstat(target)
    except FileNotFoundError:
        return None
    if stat.S_ISLNK(info.st_mode):
        _fail(target, "is a symbolic link; dyngen writes a real folder there and does not follow it (remove it)")
    if not stat.S_ISDIR(info.st_mode):
        _fail(target, "exists and is not a folder")
    if not any(os.scandir(target)):
        return None
    if not _made_by_dyngen(target) and not force:
        _fail(target, "holds files dyngen did not write; move them, choose another folder, or pass --force "
              "to replace the folder")
    REPLACED.append(f"replaced {target}/ (all of it)")
    return REPLACED[-1]


def check_file(target, inputs=(), force: bool = False) -> str | None:
    """Check the output file `target` before any work; returns a note if it replaces one."""
    target = _absolute(target)
    _check_links(target.parent)
    for ancestor in target.parents:
        if ancestor.exists():
            if not ancestor.is_dir():
                _fail(ancestor, "exists and is not a folder")
            break
    _check_inputs(target, inputs, folder=False)
    try:
        info = os.lstat(target)
    except FileNotFoundError:
        return None
    if stat.S_ISDIR(info.st_mode):
        _fail(target, "is a folder; give a file name")
    REPLACED.append(f"replaced {target}")
    return REPLACED[-1]


@contextmanager
def results_folder(target):
    """Yield a staging folder beside `target`; on success it becomes `target` (with MARKER) in
    one rename, and the previous folder is removed; on failure it is removed and `target` is
    left as it was."""
    with staged_folder(target) as staging:
        yield staging
        (staging / MARKER).write_text(_MARKER_TEXT)


def shown(path, staging: Path, target: Path) -> Path:
    """A path inside the staging folder as the user will find it after the rename."""
    path = Path(path)
    try:
        return Path(target) / path.relative_to(staging)
    except ValueError:
        return path
