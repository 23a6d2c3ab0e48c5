"""Reading files that may come from anyone: one place for the checks every input file gets.

A robot description, a parameter file or a recording is read as bytes, bounded in size,
decoded as UTF-8 (or refused with the byte offset), and, for YAML, parsed by a loader that
builds only plain data (SafeLoader), refuses duplicate keys (the last would silently win)
and aliases (the "billion laughs" expansion), and turns a too-deep nesting into an error
with a line number instead of a RecursionError. Every failure is an InputError: one line
naming the file and where.
"""

from __future__ import annotations

import os
import stat
import zlib
from pathlib import Path

from .errors import InputError, shorten

MAX_YAML_BYTES = 1 << 20  # a 40-joint description with bounds and coefficients is about 100 kB
MAX_CSV_BYTES = 1 << 30  # an hour at 1 kHz for 12 joints is about 0.5 GB of text
# Recordings of measured floats pack 3 to 10 times; a file that unpacks 50 times its size past
# 64 MB is a decompression bomb (or a recording of nothing), refused before the memory is spent.
MAX_RATIO, RATIO_FROM = 50, 64 << 20


def regular_file(path, limit: int) -> int:
    """The size of `path` if it is a regular file of at most `limit` bytes, for readers that
    open files themselves (Parquet, ROS 2 bags); a device, FIFO or folder is refused (reading
    /dev/zero or a FIFO would never end)."""
    path = Path(path)
    try:
        info = path.stat()
    except OSError as err:
        raise InputError(str(path), "", f"cannot read the file ({err.strerror or err})") from None
    if not stat.S_ISREG(info.st_mode):
        raise InputError(str(path), "", "not a regular file")
    if info.st_size > limit:
        raise InputError(path.name, "", f"file too large (at most {limit >> 20} MB)")
    return info.st_size


def regular_folder(path, limit: int, most: int = 1000) -> None:
    """A folder (a ROS 2 bag) holding only regular files (no links, no subfolders), at most
    `most` of them and `limit` bytes in all."""
    path = Path(path)
    try:
        entries = list(os.scandir(path))
    except OSError as err:
        raise InputError(str(path), "", f"cannot read the folder ({err.strerror or err})") from None
    if len(entries) > most:
        raise InputError(path.name, "", f"{len(entries)} entries; a bag folder has at most {most}")
    total = 0
    for entry in entries:
        if not entry.is_file(follow_symlinks=False):
            raise InputError(path.name, shorten(entry.name), "not a regular file (links and folders are refused)")
        total += entry.stat(follow_symlinks=False).st_size
    if total > limit:
        raise InputError(path.name, "", f"folder too large (at most {limit >> 20} MB)")


def read_bytes(path, limit: int) -> bytes:
    """The file's bytes (a .gz file: unpacked), at most `limit` of them. Anything but a regular
    file (a FIFO would block, /dev/zero never ends, a folder) is refused before a byte is read,
    the size is checked from the open file before reading, and unpacking stops at `limit`."""
    path = Path(path)
    name = path.name
    try:  # O_NONBLOCK: opening a FIFO must not wait for a writer
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as err:
        raise InputError(str(path), "", f"cannot read the file ({err.strerror or err})") from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        raise InputError(str(path), "", f"not a regular file ({_kind(info.st_mode)}); give a file")
    with os.fdopen(fd, "rb") as f:
        if info.st_size > limit:
            raise InputError(name, "", f"file too large ({info.st_size >> 20} MB; at most {limit >> 20} MB)")
        try:
            data = f.read(limit + 1)
        except OSError as err:
            raise InputError(str(path), "", f"cannot read the file ({err.strerror or err})") from None
    if len(data) > limit:  # grew while being read
        raise InputError(name, "", f"file too large (at most {limit >> 20} MB)")
    if path.suffix == ".gz":
        data = _gunzip(data, limit, name)
    return data


def _kind(mode: int) -> str:
    for test, what in ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return what
    return "not a plain file"


def _gunzip(data: bytes, limit: int, name: str) -> bytes:
    """Unpack in chunks, counting the output: a small file may unpack to gigabytes, and the
    unpacking stops at `limit`, before the memory is spent. Several gzip members follow each
    other as `cat a.gz b.gz` makes them."""
    out = bytearray()
    pending = data
    while True:
        inflater = zlib.decompressobj(16 + zlib.MAX_WBITS)
        try:
            while not inflater.eof:
                room = limit + 1 - len(out)
                chunk = inflater.decompress(pending, min(room, 1 << 20))
                pending = inflater.unconsumed_tail
                out += chunk
                if len(out) > limit:
                    raise InputError(name, "", f"unpacks to more than {limit >> 20} MB (at most {limit >> 20} MB)")
                if len(out) > max(RATIO_FROM, MAX_RATIO * len(data)):
                    raise InputError(name, "", f"unpacks to more than {MAX_RATIO} times its size "
                                     f"({len(data) >> 10} kB to over {len(out) >> 20} MB): a decompression bomb?")
                if not chunk and not pending and not inflater.eof:
                    raise InputError(name, "", "not a readable gzip file (truncated)")
        except zlib.error as err:
            raise InputError(name, "", f"not a readable gzip file ({shorten(str(err))})") from None
        pending = inflater.unused_data
        if not pending.strip(b"\0"):  # end, or the zero padding some tools write
            return bytes(out)


def read_text(path, limit: int) -> str:
    """The file as text: UTF-8 (a byte-order mark is dropped); anything else is refused."""
    data = read_bytes(path, limit)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = data[:err.start].count(b"\n") + 1
        raise InputError(Path(path).name, f"line {line}",
                         f"not UTF-8 text (byte {err.start}); save the file as UTF-8") from None


def read_yaml(path):
    """Plain data (dicts, lists, str, int, float, bool, None) from a YAML file, every scalar
    and node by one policy (dyngen.yaml_policy)."""
    from . import yaml_policy

    return yaml_policy.load(read_text(path, MAX_YAML_BYTES), Path(path).name)
