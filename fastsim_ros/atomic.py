"""Atomic file writes: a temporary file beside the target, renamed onto it once complete.

Shared by the command lines and the plots (:mod:`fastsim_ros.cli.wheelset`,
:mod:`fastsim_ros.geometry.sweep_plot`), so that a reader never sees a
half-written file and an interrupted run leaves nothing behind.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

from fastsim_ros.contact.errors import InvalidInputError


def check_target(path: Path | str) -> Path:
    """Return the directory a file ``path`` goes to; refuse a target it cannot be written as.

    Refused (:class:`InvalidInputError`, one line): a missing directory, a
    directory that is not writable, a target that is a directory.  Called
    before the work whose result it receives, and again when it is written.
    """
    path = Path(path)
    target_dir = path.parent if str(path.parent) else Path(".")
    if not target_dir.is_dir():
        raise InvalidInputError(f"{target_dir}: no such directory")
    if path.is_dir():
        raise InvalidInputError(f"{path}: is a directory")
    if not os.access(target_dir, os.W_OK | os.X_OK):
        raise InvalidInputError(f"{target_dir}: not writable")
    return target_dir


def write_atomically(path: Path | str, write: Callable[[IO[Any]], object], *,
                     binary: bool = False) -> None:
    """Write ``path`` through ``write(f)`` on a temporary file, then rename it onto ``path``.

    ``binary``: the file is opened ``"wb"``, else ``"w"`` with ``newline=""``
    (csv's convention).  A missing directory is an :class:`InvalidInputError`;
    on any failure the temporary file is removed and the error raised.
    """
    path = Path(path)
    target_dir = check_target(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=target_dir)
    except OSError as e:
        raise InvalidInputError(f"{path}: cannot write there ({e.strerror or e})") from None
    try:
        # mkstemp's file is private (0600): the result gets the mode a new file would get
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        with (os.fdopen(fd, "wb") if binary else os.fdopen(fd, "w", newline="")) as f:
            write(f)
        try:
            os.replace(tmp, path)
        except OSError as e:
            raise InvalidInputError(f"{path}: cannot write it ({e.strerror or e})") from None
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
