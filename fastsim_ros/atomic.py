"""Atomic file writes: a temporary file beside the target, renamed onto it once complete.

Shared by the command lines and the plots (:mod:`fastsim_ros.cli_wheelset`,
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


def write_atomically(path: Path | str, write: Callable[[IO[Any]], object], *,
                     binary: bool = False) -> None:
    """Write ``path`` through ``write(f)`` on a temporary file, then rename it onto ``path``.

    ``binary``: the file is opened ``"wb"``, else ``"w"`` with ``newline=""``
    (csv's convention).  A missing directory is an :class:`InvalidInputError`;
    on any failure the temporary file is removed and the error raised.
    """
    path = Path(path)
    target_dir = path.parent if str(path.parent) else Path(".")
    if not target_dir.is_dir():
        raise InvalidInputError(f"{target_dir}: no such directory")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=target_dir)
    try:
        with (os.fdopen(fd, "wb") if binary else os.fdopen(fd, "w", newline="")) as f:
            write(f)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
