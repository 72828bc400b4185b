# One BLAS thread per test process, set before numpy loads OpenBLAS: the two workers of
# `pytest -n 2` already fill the two cores, and OpenBLAS threads on top spin against the other
# worker. A full-model solve measured 34 s alone, 226 s beside a second one, 35 s beside it with
# one thread each. (Snakemake sets these for its jobs itself; the solver gains nothing from
# more threads.)
from hdwf.common.blas import one_thread_unless_set

one_thread_unless_set()

import shutil  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "data" / "paper"


@pytest.fixture
def paper_dir():
    return DATA


def copy_workflow(dest: Path, extra: tuple[str, ...] = ()) -> Path:
    """A copy of the workflow (Snakefile, config, rules and scripts, data, and ``extra`` paths) in
    ``dest``, with no results: Snakemake keeps its logs and state in the project it runs in."""
    for item in ("Snakefile", "config.yaml", "workflow", "data", *extra):
        src, dst = ROOT / item, dest / item
        dst.parent.mkdir(parents=True, exist_ok=True)
        (shutil.copytree if src.is_dir() else shutil.copy)(src, dst)
    return dest


# The test files that take minutes, longest first (`pytest -n 2 --durations=0`, summed per
# file). `pytest -n 2` hands each file to one worker whole (pyproject.toml): starting the long
# ones first lets both workers finish together instead of one running a late long file alone.
LONGEST_FIRST = [
    "validation/test_hidden_effects_dense.py",
    "validation/test_hidden_effects.py",
    "workflow/test_workflow_e2e.py",
    "workflow/test_slurm.py",
]


def pytest_collection_modifyitems(items):
    # every end-to-end run of a Snakemake target is slow; `pytest -m "not slow"` leaves them out
    for item in items:
        if item.get_closest_marker("e2e"):
            item.add_marker(pytest.mark.slow)
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.relative_to(ROOT / "tests").as_posix(), len(rank)))


def write_table(df: pd.DataFrame, tmp_path, name: str = "m.csv") -> Path:
    """``df`` written to ``tmp_path / name``, CSV or Parquet by the name's extension."""
    path = tmp_path / name
    if name.endswith(".csv"):
        df.to_csv(path, index=False)
    else:
        df.to_parquet(path, index=False)
    return path


def masing_loop(T: np.ndarray, loop: float) -> np.ndarray:
    """A Masing hysteresis loop along a torque path, written out branch by branch (independent of
    the effect's code in hdwf.fe.cycle): virgin curve c T|T|, after a reversal at (T_r, θ_r)
    θ_r + c (T - T_r)|T - T_r| / 2, c = loop / T_max², so in the test 0 -> +T -> 0 -> -T -> 0
    the branches are ``loop`` apart at zero torque."""
    c = loop / np.max(np.abs(T)) ** 2
    out, t_r, th_r, virgin, d_prev = [], 0.0, 0.0, True, 0.0
    for k, t in enumerate(T):
        if k:
            d = np.sign(t - T[k - 1])
            if d_prev and d and d != d_prev:
                t_r, th_r, virgin = T[k - 1], out[-1], False
            d_prev = d or d_prev
        out.append(c * t * abs(t) if virgin else th_r + c * (t - t_r) * abs(t - t_r) / 2)
    return np.array(out)
