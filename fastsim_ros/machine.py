"""The one machine line every benchmark and validation script prints beside its figures.

A figure means little without the machine it was measured on:
platform, CPU model, cores (and how many this process may use), the load
average when the line was taken (a shared machine slows runs), Python,
numpy and numba (where installed).
"""

from __future__ import annotations

import os
import platform


def cpu_model() -> str:
    """Return the CPU's model name from ``/proc/cpuinfo`` (``unknown CPU`` elsewhere)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def machine() -> str:
    """Describe the machine: platform, CPU model, cores, load, Python, numpy and numba."""
    import numpy as np

    try:
        import numba
        compiled = f", numba {numba.__version__}"
    except ImportError:
        compiled = ""
    cores = os.cpu_count()
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else cores
    load = ", load average %.2f %.2f %.2f" % os.getloadavg() if hasattr(os, "getloadavg") \
        else ""
    return (f"{platform.platform()}; {cpu_model()}; {cores} cores ({usable} usable){load}; "
            f"Python {platform.python_version()}, numpy {np.__version__}{compiled}")
