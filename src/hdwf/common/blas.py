"""One BLAS thread per process unless the environment says otherwise.

The solver's dense work is small blocks (a few hundred pairs), where OpenBLAS threads cost more
than they give, and beside any other work on the machine spin against it (a study solve by hand:
8.0 s with one thread, 12.0 s with two; ``benchmarks/bench_blas_threads.py``). Snakemake gives each job
the rule's threads (one); the entry points that run outside it (the ``hdwf`` command, a rule
script run by hand, the benchmarks, the tests) call ``one_thread_unless_set`` before numpy
loads, since OpenBLAS reads these variables only then.
"""

from __future__ import annotations

import os

BLAS_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def one_thread_unless_set() -> None:
    """Set every BLAS thread count the environment leaves unset to 1 (a set one is kept)."""
    for var in BLAS_VARS:
        os.environ.setdefault(var, "1")
