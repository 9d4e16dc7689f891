"""Inputs and outputs that are fsspec URLs (``s3://``, ``file://``): fetched, staged, committed.

A task whose input is a URL replays a local copy of it (fetched into a
temporary directory on the worker); a task whose output directory is a URL
replays into a local temporary directory and then commits: each file is
uploaded under a temporary name inside ``OUT`` and moved to its final name,
the bag's ``metadata.yaml`` last (a rosbag2 bag is a bag only once that file
is there), so a reader never sees a half-written output.  Anything else is
a local path and stays one.
"""

from __future__ import annotations

import os
import posixpath
from pathlib import Path
from typing import Any

#: the bag file that makes an output directory a bag: moved into place last
METADATA = "metadata.yaml"
#: where an overwriting commit moves the outputs it replaces, inside its staging directory
REPLACED = ".replaced"


def is_url(path: Any) -> bool:
    """Tell whether ``path`` is an fsspec URL (``protocol://...``) rather than a local path."""
    return isinstance(path, str) and "://" in path


def filesystem(url: str) -> tuple[Any, str]:
    """Return the fsspec filesystem of ``url`` and the path on it."""
    from fsspec.core import url_to_fs  # type: ignore[import-untyped]
    fs, path = url_to_fs(url)
    return fs, path.rstrip("/") or path


def join(base: str | Path, name: str) -> str | Path:
    """Return ``base/name`` for a local path or a URL."""
    if is_url(base):
        return posixpath.join(str(base).rstrip("/"), name)
    return Path(base) / name


def basename(url: str) -> str:
    """Return the last part of a URL's path (a trailing slash ignored)."""
    return posixpath.basename(url.rstrip("/"))


def exists(path: str | Path) -> bool:
    """Tell whether there is anything at a local path or a URL (a broken symlink counts)."""
    if is_url(path):
        fs, p = filesystem(str(path))
        return bool(fs.exists(p))
    return os.path.lexists(path)


def is_file(path: str | Path) -> bool:
    """Tell whether a local path or a URL is something other than a directory."""
    if is_url(path):
        fs, p = filesystem(str(path))
        return bool(fs.exists(p)) and not fs.isdir(p)
    return os.path.lexists(path) and not Path(path).is_dir()


def makedirs(directory: str | Path) -> None:
    """Make a local directory or a directory URL (and its parents) if missing."""
    if is_url(directory):
        fs, p = filesystem(str(directory))
        fs.makedirs(p, exist_ok=True)
    else:
        Path(directory).mkdir(parents=True, exist_ok=True)


def fetch(url: str, into: Path) -> Path:
    """Copy the input at ``url`` (a bag directory or an ``.mcap``) into ``into``; return it."""
    fs, path = filesystem(url)
    if not fs.exists(path):
        raise FileNotFoundError(f"{url}: no such file or directory")
    into.mkdir(parents=True, exist_ok=True)
    local = into / basename(url)
    if fs.isdir(path):
        local.mkdir(parents=True)
        for entry in fs.ls(path, detail=False):
            if fs.isfile(entry):
                fs.get(entry, str(local / posixpath.basename(entry)))
    else:
        fs.get(path, str(local))
    return local


#: the empty file that marks an attempt's staging directory at a URL (from its start)
MARK = ".attempt"


def mark(url: str, staging_name: str) -> None:
    """Make ``url/staging_name/`` with its :data:`MARK`: an attempt's first act."""
    fs, root = filesystem(url)
    staging = posixpath.join(root, staging_name)
    fs.makedirs(staging, exist_ok=True)
    fs.pipe_file(posixpath.join(staging, MARK), b"")


def _moves(fs: Any, root: str, staging: str, moves: list[tuple[str, str]]) -> None:
    """Move staged files into place (``metadata.yaml`` last: callers order them)."""
    from fastsim_ros.replay import faults
    for tmp, final in moves:
        fs.makedirs(posixpath.dirname(final), exist_ok=True)
        fs.mv(tmp, final)
        faults.pause("commit")


def commit(local_out: Path, names: list[str], url: str, staging_name: str,
           journal: tuple[str, bytes] | None = None,
           replace: list[str] | None = None) -> list[str]:
    """Upload ``names`` (files and bag directories in ``local_out``) to the directory ``url``.

    Staged under ``url/staging_name/`` and moved into place file by file,
    each bag's ``metadata.yaml`` last; return the final URLs.  ``journal``
    (a file name and its bytes): written into the staging directory (whole:
    under a temporary name, then moved) once everything is uploaded and
    before the first move; the staging directory then stays (the journal
    in it) for :func:`finish_commit`, and for the caller to remove.
    ``replace``: names in ``url`` (the outputs of an earlier run, and any
    target not written this time) moved aside into the staging directory's
    :data:`REPLACED` once everything is uploaded, and moved back if a move
    fails.  Raises ``OSError`` (the caller removes what was staged:
    :func:`remove`).
    """
    fs, root = filesystem(url)
    staging = posixpath.join(root, staging_name)
    moves: list[tuple[str, str]] = []
    last: list[tuple[str, str]] = []
    for name in names:
        src = local_out / name
        files = sorted(p for p in src.rglob("*") if p.is_file()) if src.is_dir() else [src]
        for f in files:
            rel = f.relative_to(local_out).as_posix()
            tmp, final = posixpath.join(staging, rel), posixpath.join(root, rel)
            fs.makedirs(posixpath.dirname(tmp), exist_ok=True)
            fs.put_file(str(f), tmp)
            (last if f.name == METADATA else moves).append((tmp, final))
    if journal is not None:
        file, data = journal
        fs.pipe_file(posixpath.join(staging, file + ".tmp"), data)
        fs.mv(posixpath.join(staging, file + ".tmp"), posixpath.join(staging, file))
    aside: list[str] = []
    try:
        for name in replace or ():
            final = posixpath.join(root, name)
            if fs.exists(final):
                fs.mv(final, posixpath.join(staging, REPLACED, name), recursive=True)
                aside.append(name)
        _moves(fs, root, staging, moves + last)
    except OSError:
        for name in aside:   # the new output (what of it was moved) out, the old one back
            final = posixpath.join(root, name)
            if fs.exists(final):
                fs.rm(final, recursive=True)
            fs.mv(posixpath.join(staging, REPLACED, name), final, recursive=True)
        raise
    if journal is None:
        remove(url, staging_name)
    prefix = url.rstrip("/")
    return [f"{prefix}/{name}" for name in names]


def finish_commit(url: str, staging_name: str, journal: str) -> bytes:
    """Move what a journalled :func:`commit` had not moved yet into place; return the journal.

    For an attempt that died between its moves (or after them): whatever
    is still in its staging directory, ``metadata.yaml`` last.
    """
    fs, root = filesystem(url)
    staging = posixpath.join(root, staging_name)
    data = bytes(fs.cat_file(posixpath.join(staging, journal)))
    moves: list[tuple[str, str]] = []
    last: list[tuple[str, str]] = []
    for tmp in sorted(fs.find(staging)):
        rel = posixpath.relpath(tmp, staging)
        if rel in (journal, MARK) or rel.split("/")[0] == REPLACED:
            continue
        (last if posixpath.basename(rel) == METADATA else moves).append(
            (tmp, posixpath.join(root, rel)))
    _moves(fs, root, staging, moves + last)
    return data


def restore_replaced(url: str, staging_name: str) -> None:
    """Move the outputs a commit set aside in ``url/staging_name`` back where none took over."""
    fs, root = filesystem(url)
    aside = posixpath.join(root, staging_name, REPLACED)
    try:
        for old in fs.ls(aside, detail=False):
            final = posixpath.join(root, posixpath.basename(old.rstrip("/")))
            if not fs.exists(final):
                fs.mv(old, final, recursive=True)
    except OSError:
        pass


def remove(url: str, name: str) -> None:
    """Remove ``url/name`` (a staging directory or a committed output) if it is there."""
    fs, root = filesystem(url)
    path = posixpath.join(root, name)
    try:
        if fs.exists(path):
            fs.rm(path, recursive=True)
    except OSError:
        pass


def listing(directory: str | Path) -> list[str]:
    """Return the names in a local directory or a directory URL (none if it is missing)."""
    if is_url(directory):
        fs, root = filesystem(str(directory))
        try:
            return [posixpath.basename(p.rstrip("/")) for p in fs.ls(root, detail=False)]
        except (FileNotFoundError, NotADirectoryError):
            return []
    try:
        return [p.name for p in Path(directory).iterdir()]
    except OSError:
        return []
