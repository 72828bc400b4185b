"""Keep freed memory in the process for reuse (glibc's allocator), for long numeric runs.

A contact solve allocates and frees arrays of a few megabytes hundreds of times (the bodies'
back-substitution blocks, the dense active-set matrices).  glibc serves such blocks with fresh
``mmap`` pages and gives them back on ``free``, so every new block is faulted in and zeroed by
the kernel again: some 190 000 page faults and 0.4-0.8 s of system time in one HD 42 design
(an eighth of the default target's CPU time went to the kernel).  With the mmap threshold at
glibc's largest (32 MB) and the heap's top not trimmed below 1 GB, freed blocks stay in the
heap and are reused: a third of the faults and of the system time (``benchmarks/bench_solve.py``,
``docs/benchmarks.md``).  Results are unchanged (the same arithmetic in other memory).

Only glibc (Linux) has these knobs; elsewhere ``keep_freed_memory`` does nothing and says so.
"""

from __future__ import annotations

import ctypes
import os
import sys

M_TRIM_THRESHOLD = -1        # glibc's mallopt parameters (malloc.h)
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD_BYTES = 32 * 2**20    # glibc's largest accepted (HEAP_MAX_SIZE / 2 on 64-bit)
TRIM_THRESHOLD_BYTES = 2**30
# the same settings for the processes this one starts (a spawned pool's workers): glibc reads
# them when it starts
ENVIRONMENT = {"MALLOC_MMAP_THRESHOLD_": str(MMAP_THRESHOLD_BYTES),
               "MALLOC_TRIM_THRESHOLD_": str(TRIM_THRESHOLD_BYTES)}


def keep_freed_memory() -> bool:
    """Set glibc's mmap and trim thresholds for this process and the ones it starts.

    Returns True if glibc took both settings, False where there is no glibc (then nothing
    changes).
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL("libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):       # not glibc (e.g. musl)
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    taken = (mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES) == 1
             and mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD_BYTES) == 1)
    if taken:
        os.environ.update(ENVIRONMENT)
    return taken
