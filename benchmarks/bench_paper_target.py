"""Wall time of `snakemake --cores 2 paper` from an empty results/ (median of N runs).

Each run works in a fresh temporary copy of the workflow, so nothing is reused.
Usage: .venv/bin/python benchmarks/bench_paper_target.py [--runs 3]
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _workspace import copy_workflow  # noqa: E402


def one_run() -> float:
    with tempfile.TemporaryDirectory(prefix="hdwf-bench-") as tmp:
        tmp = Path(tmp)
        copy_workflow(tmp)
        snakemake = str(Path(sys.executable).with_name("snakemake"))
        t0 = time.perf_counter()
        subprocess.run([snakemake, "--cores", "2", "paper", "--quiet"], cwd=tmp, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return time.perf_counter() - t0


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    times = [one_run() for _ in range(args.runs)]
    print("runs (s):", " ".join(f"{t:.1f}" for t in times))
    print(f"median: {statistics.median(times):.1f} s")


if __name__ == "__main__":
    main()
