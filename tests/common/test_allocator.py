"""Freed memory kept for reuse (``hdwf.common.allocator``): checked in fresh processes, so the
test process's own allocator is left as it is."""

import subprocess
import sys

import pytest

from hdwf.common import allocator

# four 8 MB arrays made and freed 20 times: 160 arrays of 1954 pages each if every one were
# faulted in afresh
CHURN = """
import os, resource, sys
import numpy as np
from hdwf.common.allocator import ENVIRONMENT, keep_freed_memory
kept = keep_freed_memory()
for _ in range(3):
    x = [np.ones(1_000_000) for _ in range(4)]; del x
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(20):
    x = [np.ones(1_000_000) for _ in range(4)]; del x
faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
print(kept, faults, all(os.environ.get(k) == v for k, v in ENVIRONMENT.items()))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt only")
def test_freed_blocks_are_reused_without_page_faults():
    """After the first rounds, blocks of the size a back-substitution allocates come back from
    the heap: under 1 % of the 312 000 pages that 160 fresh 8 MB arrays would fault in; and
    the settings are in the environment for the processes this one starts."""
    out = subprocess.run([sys.executable, "-c", CHURN], capture_output=True, text=True, check=True)
    kept, faults, in_environment = out.stdout.split()
    assert kept == "True" and in_environment == "True"
    assert int(faults) < 0.01 * 160 * 1954


def test_no_glibc_changes_nothing(monkeypatch):
    """Elsewhere than Linux nothing is set and the call says so."""
    monkeypatch.setattr(allocator.sys, "platform", "darwin")
    monkeypatch.delenv("MALLOC_MMAP_THRESHOLD_", raising=False)
    assert allocator.keep_freed_memory() is False
    assert "MALLOC_MMAP_THRESHOLD_" not in allocator.os.environ
