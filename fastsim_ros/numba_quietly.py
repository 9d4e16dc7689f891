"""Import numba without its optional ``coverage`` hook: imported first by the console scripts.

numba imports ``coverage`` when it is installed (colcon's test tools bring
it) only to trace the lines of jitted code in coverage runs; that import is
0.5 s of the node's 1-2 s start-up here.  The node and the replay are not run
under coverage, so numba is loaded with ``coverage`` hidden, unless coverage
is already running; ``coverage`` is importable again afterwards.
"""

import sys

_HIDE = "coverage" not in sys.modules
if _HIDE:
    sys.modules["coverage"] = None  # type: ignore[assignment]
try:
    import numba  # noqa: F401
finally:
    if _HIDE:
        del sys.modules["coverage"]
