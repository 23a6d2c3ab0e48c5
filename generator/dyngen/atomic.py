"""Write a whole output folder or file so that a failure leaves the old one untouched."""

from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def staged_folder(target: Path):
    """Yield an empty staging folder beside `target`; on success it replaces `target` in one
    rename (the previous folder is then removed); on failure it is removed and `target` is left
    as it was."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{target.name}.new-", dir=target.parent))
    os.chmod(staging, 0o777 & ~_umask())  # mkdtemp makes it private; the output folder is not
    try:
        yield staging
        old = None
        if os.path.lexists(target):
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
            os.rmdir(old)
            os.rename(target, old)
        os.rename(staging, target)
        if old is not None:
            shutil.rmtree(old)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise


def write_folder(target: Path, files: dict[str, str]) -> None:
    """Replace folder `target` by exactly `files` (name -> text), all at once."""
    with staged_folder(target) as staging:
        for name, text in sorted(files.items()):
            (staging / name).write_text(text)


def write_file(target: Path, text: str) -> None:
    _replace(target, "w", lambda f: f.write(text))


def write_figure(target: Path, fig, dpi: int) -> Path:
    """A matplotlib figure as PNG; returns the path."""
    _replace(target, "wb", lambda f: fig.savefig(f, format="png", dpi=dpi))
    return Path(target)


def _replace(target: Path, mode: str, write) -> None:
    """write(file) into a temporary file beside target, then rename it over target."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
    try:
        with os.fdopen(fd, mode) as f:
            write(f)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes it private; the output file is not
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
