"""A rule script run by hand with one BLAS thread against more (``hdwf.common.blas``).

Outside Snakemake nothing sets the BLAS libraries' thread counts, and OpenBLAS then starts one
thread a core. This runs ``workflow/scripts/fe_solve.py`` by hand (its example wildcards: study
``fe``, hd42-lhs-01, the studies' model) in a temporary copy of the workflow, R times for each
thread count, the counts alternating, with ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` and
``MKL_NUM_THREADS`` set to it, and prints the median, min and max of the run's wall time and of
the solve's own ``solve_s``. Run it with nothing beside it, or beside a known load to see what
threads cost there.

Usage: .venv/bin/python benchmarks/bench_blas_threads.py [--threads 1,2] [--repeats 3]
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pyarrow.parquet as pq

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _workspace import copy_workflow  # noqa: E402

from hdwf.common.blas import BLAS_VARS  # noqa: E402

SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))
ROW = Path("results/fe/hd42/designs/hd42-lhs-01.parquet")


def run_once(project: Path, threads: int) -> tuple[float, float]:
    """Wall time of one hand run of fe_solve.py and the solve_s it records."""
    env = os.environ | {var: str(threads) for var in BLAS_VARS}
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "workflow/scripts/fe_solve.py"], cwd=project, env=env, check=True,
                   stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    return wall, float(pq.read_table(project / ROW).column("solve_s")[0].as_py())


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--threads", default="1,2", help="thread counts, comma-separated")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    counts = [int(t) for t in args.threads.split(",")]
    with tempfile.TemporaryDirectory(prefix="hdwf-bench-") as tmp:
        project = copy_workflow(Path(tmp))
        subprocess.run([SNAKEMAKE, "results/fe/hd42/designs.parquet", "--cores", "1", "--quiet"],
                       cwd=project, check=True, capture_output=True)
        times: dict[int, list[tuple[float, float]]] = {t: [] for t in counts}
        for _ in range(args.repeats):
            for t in counts:
                times[t].append(run_once(project, t))
    for t in counts:
        wall = [w for w, _ in times[t]]
        solve = [s for _, s in times[t]]
        print(f"{t} thread(s): wall median {statistics.median(wall):.2f} s (min {min(wall):.2f}, max {max(wall):.2f}); "
              f"solve_s median {statistics.median(solve):.2f} s (min {min(solve):.2f}, max {max(solve):.2f})")


if __name__ == "__main__":
    main()
