"""Errors of the front ends (the node, the command lines, the parameters): one line each.

The physics, the geometry, the message adapters and the replay keep theirs
in their own ``errors`` modules.
"""

from __future__ import annotations


class ParameterError(ValueError):
    """A parameter value outside its type or range; the message names both."""


class StartupError(Exception):
    """A configuration the node cannot start with: reported in one line, exit 2."""


class UsageError(Exception):
    """A command line that cannot be run: reported in one line, exit status 2."""
