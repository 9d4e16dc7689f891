"""Wheel-rail creep forces with Kalker's FastSim, extended to non-elliptical areas by MAE.

Importing the package points numba's on-disk cache of the compiled kernels
at a writable place shared by every run of the same installed files
(``$NUMBA_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/fastsim_ros/numba``,
``~/.cache`` by default): numba's own default, ``__pycache__`` beside the
source, is not writable in a read-only install tree, and a node that
compiles its kernels at start takes about 18 s to reach its first wrench.
numba keys each entry on the source file's path and time stamp, so the
checkout and the install tree keep separate entries.
"""

import os
import tempfile


def _numba_cache_dir() -> str:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    for path in (os.path.join(base, "fastsim_ros", "numba"),
                 os.path.join(tempfile.gettempdir(), f"fastsim_ros-numba-{os.getuid()}")):
        try:
            os.makedirs(path, exist_ok=True)
        except OSError:
            continue
        if os.access(path, os.W_OK):
            return path
    return ""


if "NUMBA_CACHE_DIR" not in os.environ:
    _cache = _numba_cache_dir()
    if _cache:
        os.environ["NUMBA_CACHE_DIR"] = _cache
