"""The entry points outside Snakemake (the ``hdwf`` command, a rule script run by hand) load
numpy with one BLAS thread unless the environment asks for another: OpenBLAS reads its thread
count once, when numpy first loads, so the variable must be set before that import."""

import os
import subprocess
import sys

import pytest

from hdwf.common.blas import BLAS_VARS

from conftest import ROOT

# prints each BLAS variable as it is at the moment numpy is first imported
SPY = """
import os, sys
class Spy:
    seen = False
    def find_spec(self, name, path=None, target=None):
        if name == "numpy" and not Spy.seen:
            Spy.seen = True
            print("AT_NUMPY", *(os.environ.get(v) for v in {vars!r}))
        return None
sys.meta_path.insert(0, Spy())
sys.path.insert(0, {scripts!r})
import {module}
import numpy
"""


def _at_numpy(module: str, env_extra: dict[str, str]) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k not in BLAS_VARS} | env_extra
    code = SPY.format(vars=BLAS_VARS, scripts=str(ROOT / "workflow" / "scripts"), module=module)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True, cwd=ROOT).stdout
    line = next(l for l in out.splitlines() if l.startswith("AT_NUMPY"))
    return line.split()[1:]


@pytest.mark.parametrize("module", ["hdwf.cli", "_helpers"])
def test_numpy_loads_with_one_blas_thread_unless_the_environment_sets_one(module):
    assert _at_numpy(module, {}) == ["1", "1", "1"]
    assert _at_numpy(module, {"OPENBLAS_NUM_THREADS": "3"}) == ["1", "3", "1"]
