"""Imported first by the benchmarks that time single solves: one BLAS thread, as the studies'
jobs have (set before numpy loads), and ``hdwf`` importable from a checkout not installed."""

import sys
from pathlib import Path

try:
    import hdwf  # noqa: F401
except ImportError:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from hdwf.common.blas import one_thread_unless_set  # noqa: E402

one_thread_unless_set()
