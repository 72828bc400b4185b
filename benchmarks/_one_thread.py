"""Imported first by the benchmarks that time single solves: one BLAS thread, as the studies'
jobs have (set before numpy loads), and ``hdwf`` importable from a checkout not installed."""

import os
import sys
from pathlib import Path

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
try:
    import hdwf  # noqa: F401
except ImportError:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
