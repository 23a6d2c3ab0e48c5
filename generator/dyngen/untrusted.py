"""Reading files that may come from anyone: one place for the checks every input file gets.

A robot description, a parameter file or a recording is read as bytes, bounded in size,
decoded as UTF-8 (or refused with the byte offset), and, for YAML, parsed by a loader that
builds only plain data (SafeLoader), refuses duplicate keys (the last would silently win)
and aliases (the "billion laughs" expansion), and turns a too-deep nesting into an error
with a line number instead of a RecursionError. Every failure is an InputError: one line
naming the file and where.
"""

from __future__ import annotations

import gzip
import io
import os
import stat
import zlib
from pathlib import Path

import yaml

from .errors import InputError, shorten

MAX_YAML_BYTES = 4 << 20  # a 20-joint description with bounds is about 20 kB
MAX_CSV_BYTES = 2 << 30  # an hour at 1 kHz for 12 joints is about 0.5 GB of text


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
    path = Path(path)
    try:
        with open(path, "rb") as f:
            data = f.read(limit + 1)
    except OSError as err:
        raise InputError(str(path), "", f"cannot read the file ({err.strerror or err})") from None
    if path.suffix == ".gz":
        try:
            data = _gunzip(data, limit)
        except (OSError, EOFError, zlib.error) as err:
            raise InputError(path.name, "", f"not a readable gzip file ({err or 'truncated'})") from None
    if len(data) > limit:
        raise InputError(path.name, "", f"file too large (at most {limit >> 20} MB)")
    return data


def _gunzip(data: bytes, limit: int) -> bytes:
    with gzip.GzipFile(fileobj=io.BytesIO(data)) as f:
        return f.read(limit + 1)  # bounded: a small file may unpack to gigabytes


def read_text(path, limit: int) -> str:
    """The file as text: UTF-8 (a byte-order mark is dropped); anything else is refused."""
    data = read_bytes(path, limit)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = data[:err.start].count(b"\n") + 1
        raise InputError(Path(path).name, f"line {line}",
                         f"not UTF-8 text (byte {err.start}); save the file as UTF-8") from None


class _Loader(yaml.SafeLoader):
    """SafeLoader without duplicate keys and without aliases."""

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise yaml.constructor.ConstructorError(None, None, "aliases (*name) are not allowed",
                                                    event.start_mark)
        return super().compose_node(parent, index)

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                duplicate = key in seen
            except TypeError:  # an unhashable key: the base class reports it
                break
            if duplicate:
                raise yaml.constructor.ConstructorError(None, None, f"duplicate key {shorten(key)!s}",
                                                        key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def read_yaml(path):
    """Plain data (dicts, lists, str, int, float, bool, None) from a YAML file."""
    name = Path(path).name
    text = read_text(path, MAX_YAML_BYTES)
    try:
        return yaml.load(text, Loader=_Loader)  # noqa: S506 -- _Loader is a SafeLoader
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None) or getattr(err, "context_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        if "could not determine a constructor" in problem:
            problem = "tags such as !!python/... are not allowed (plain data only)"
        raise InputError(name, where, f"malformed YAML: {shorten(problem)}") from None
    except RecursionError:
        raise InputError(name, "", "malformed YAML: nested too deeply") from None
