"""Wheel-rail creep forces with Kalker's FastSim, extended to non-elliptical areas by MAE.

Importing the package points numba's on-disk cache of the compiled kernels
at a writable place shared by every run of the same installed files
(``$NUMBA_CACHE_DIR`` if the user set it, else ``$XDG_CACHE_HOME/fastsim_ros/numba/<digest
of the kernel sources>``, ``~/.cache`` by default, chosen again by every process
for the files it imports): numba's own default, ``__pycache__`` beside the
source, is not writable in a read-only install tree, and a node that
compiles its kernels at start takes about 18 s to reach its first wrench.
numba keys each entry on the source file's path and time stamp, so the
checkout and the install tree keep separate entries.
"""

import hashlib
import os
import sys
import tempfile
from typing import Any


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


#: the sources the compiled kernels are built from: numba checks only the time
#: stamp of the file a kernel is defined in, not of what it compiles in from
#: elsewhere (``rules.py`` into ``kernels.py``, ``transient.py`` into
#: ``pipeline/kernels.py``, ``msg_adapters/patch.py``'s constants), so the cache
#: directory this package chooses is keyed on their contents and a changed formula
#: can never load a stale kernel from it (``test_pipeline_kernels`` checks the list
#: against the sources: every module with compiled functions, and what they import,
#: is here).  A ``NUMBA_CACHE_DIR`` the user set is kept as it is: there numba's
#: per-file time stamps are the only key, and a kernel changed in one file and
#: compiled into another's can load stale (clear that directory after editing)
_KERNEL_SOURCES = ("contact/kernels.py", "contact/rules.py", "contact/knee.py", "contact/lobes.py",
                   "contact/slip_power.py",
                   "contact/transient.py",
                   "pipeline/kernels.py", "replay/kernels.py",
                   "../msg_adapters/patch_kernels.py", "../msg_adapters/patch.py")


def _sources_digest() -> str:
    digest = hashlib.sha256()
    here = os.path.dirname(os.path.abspath(__file__))
    for name in _KERNEL_SOURCES:
        try:
            with open(os.path.join(here, name), "rb") as f:
                digest.update(f.read())
        except OSError:
            digest.update(name.encode())
    return digest.hexdigest()[:16]


#: the directory an import of this package chose, exported with it: a child process
#: (the installed node started by a test) inherits ``NUMBA_CACHE_DIR`` and would
#: otherwise cache its own tree's kernels under its parent's digest (a checkout's
#: parent starting the installed node: a cold compile whenever the checkout's kernel
#: sources differ from the install's); a directory the user set is kept
_CHOSEN = "FASTSIM_ROS_NUMBA_CACHE_DIR"

if "NUMBA_CACHE_DIR" not in os.environ or (
        os.environ["NUMBA_CACHE_DIR"] == os.environ.get(_CHOSEN)):
    _cache = _numba_cache_dir()
    if _cache:
        _cache = os.path.join(_cache, _sources_digest())
        os.makedirs(_cache, exist_ok=True)
        os.environ["NUMBA_CACHE_DIR"] = os.environ[_CHOSEN] = _cache
        if "numba.core.config" in sys.modules:
            # numba read its settings when it was imported (a script that imports numba
            # before this package): its cache would stay in __pycache__, keyed on each
            # file's own time stamp, and a kernel compiled in from another file
            # (rolling_sweep into transient.py's solves) would load stale machine code.
            # Only the cache's directory is set: reload_config() would also reset what
            # the script set in code (numba.config.DISABLE_JIT for a coverage run)
            _config: Any = sys.modules["numba.core.config"]
            _config.CACHE_DIR = _cache
