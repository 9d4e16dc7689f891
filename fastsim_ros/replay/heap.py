"""The C heap of a replaying process: freed chunk buffers kept for the next chunks.

A replay allocates and frees a buffer of about a megabyte per chunk
(decompressed records) and a few more for the chunk's arrays.  glibc
serves blocks of that size by ``mmap`` until a process has freed one (its
threshold then adapts), and returns freed memory at the heap's top to the
kernel: in a fresh process (a Dask worker, a command line, a pool's worker)
every chunk then comes back as new pages, one page fault per 4 kB, about
900 per 0.5 s bag here, a third of its replay's time.
:func:`keep_freed_memory` sets both thresholds once per process so that
freed buffers are reused: the heap keeps what the replay's window held at
most (``mcap.windows``: 32 MB of chunks, plus their arrays), up to
:data:`TRIM_BYTES`.  On a C library other than glibc it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util

#: blocks below this size come from the heap (glibc's M_MMAP_THRESHOLD), bytes
MMAP_BYTES = 64 << 20
#: free memory at the heap's top kept for reuse (glibc's M_TRIM_THRESHOLD), bytes
TRIM_BYTES = 128 << 20
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_done = False


def keep_freed_memory() -> bool:
    """Keep freed blocks of up to :data:`MMAP_BYTES` in the heap; return whether it applied."""
    global _done
    if _done:
        return True
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc: its own allocator's policy stays
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    _done = bool(mallopt(_M_MMAP_THRESHOLD, MMAP_BYTES)) and bool(
        mallopt(_M_TRIM_THRESHOLD, TRIM_BYTES))
    return _done
