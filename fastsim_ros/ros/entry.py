"""The nodes' console scripts: a signal while start-up imports the node ends it quietly.

The node's module imports rclpy (a third of a second, more on a cold
disk; numpy, numba and the kernels load later, once the parameters are
checked) before :func:`fastsim_ros.ros.node.main` can put its own signal
handling in place, and a console script imports its target's module before
calling it: a SIGINT there would print a ``KeyboardInterrupt`` traceback
from inside an import and a SIGTERM would kill the process (exit -15),
where the node stops with exit 0.  So the scripts start here, in a
module that imports nothing heavy: SIGINT and SIGTERM end the process with
status 0 until the node's module is loaded, then Python's own handlers are
back for :func:`fastsim_ros.ros.node.main` (which installs the node's).
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable
from typing import Any


#: whether a signal arrived while the node's module was being imported
_signalled = [False]


def _quiet_exit(signum: int, frame: Any) -> None:
    _signalled[0] = True
    raise SystemExit(0)


def _load(name: str) -> Callable[[], int]:
    """Import the node's module with the quiet handlers in place; return its ``name``."""
    previous = {s: signal.signal(s, _quiet_exit) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        from fastsim_ros.ros import node
    except BaseException:
        # the exit raised inside a C extension's import surfaces as that import's
        # ImportError (rclpy's, with a misleading "isn't present on the system")
        if _signalled[0]:
            raise SystemExit(0) from None
        raise
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    main: Callable[[], int] = getattr(node, name)
    return main


def node() -> int:
    """``fastsim_node``: :func:`fastsim_ros.ros.node.main`."""
    return _load("main")()


def lifecycle_node() -> int:
    """``fastsim_lifecycle_node``: :func:`fastsim_ros.ros.node.main_lifecycle`."""
    return _load("main_lifecycle")()


if __name__ == "__main__":
    sys.exit(node())
