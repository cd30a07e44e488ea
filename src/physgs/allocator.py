"""glibc's allocator kept from handing back, every iteration, the memory the next one needs.

By default glibc serves an allocation above a dynamic threshold (128 KiB at start, raised to the
size of the largest freed such block, at most 32 MiB) with fresh pages from mmap, and returns the
free memory at the heap's top to the system once more than twice that threshold is free. A
training iteration allocates and frees the same ~10 MB every time (the rasterizer's images, row
buffers and per-pair gradients, torch's temporaries), so each iteration pays the page faults of
fresh pages again: ~2.5 of the ~16 CPU ms of the rasterizer's forward + backward on the medium
tree (``benchmarks/rasterizer.py``). Fixed thresholds keep freed pages in the process for reuse.
"""

from __future__ import annotations

import ctypes
import ctypes.util

#: glibc mallopt parameters (malloc.h)
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
#: allocations up to this size come from the heap (glibc's own ceiling of its dynamic threshold)
MMAP_THRESHOLD_MIB = 32
#: free memory at the heap's top kept before any is returned to the system
TRIM_THRESHOLD_MIB = 256


def retain_freed_memory() -> bool:
    """Fix glibc's mmap and trim thresholds (MMAP_THRESHOLD_MIB, TRIM_THRESHOLD_MIB) for this
    process.

    Returns:
        True where glibc took both, False under another C library (macOS, musl), where nothing
            changes: it only saves page faults, results are the same either way.
    """
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError):
        return False
    ok = mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_MIB << 20) == 1
    return ok and mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD_MIB << 20) == 1
