"""The replay's exceptions: one line each, naming the file."""

from __future__ import annotations


class BadInput(Exception):
    """An input that cannot be replayed: corrupt, truncated, empty, not a bag (exit 2)."""


class OutputError(Exception):
    """An output that cannot be written: disk full, permissions, a target that appeared."""


class McapError(Exception):
    """A file that does not follow the MCAP format where the replay reads it."""


class ClusterError(Exception):
    """The cluster cannot be reached, or was lost while replaying."""


def problem(e: BaseException) -> str:
    """Return one line describing ``e`` (the type named unless it is one of ours)."""
    text = " ".join(str(e).split()) or type(e).__name__
    return text if isinstance(e, (BadInput, OutputError)) else f"{type(e).__name__}: {text}"
