"""Do two finished runs give the same results? Every Parquet table of one against the other.

Walks ``results/`` of run A and compares each Parquet table with the same path under run B
(``pandas.testing.assert_frame_equal``, exact), leaving out the columns that time a job
(``solve_s``, ``mesh_s`` and any other ``*_s``, ``seconds``): the check that a change of code
or machine left every number as it was. Prints the tables that differ or are missing in B and
a count; exits 1 if any differ or are missing.

Usage: .venv/bin/python benchmarks/compare_runs.py RUN_A RUN_B
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd


def timing_column(name: str) -> bool:
    return name.endswith("_s") or name == "seconds"


def compare(a: Path, b: Path) -> tuple[int, list[str]]:
    """The number of tables compared and a line for each that differs or is missing in ``b``."""
    problems, n = [], 0
    for table in sorted((a / "results").rglob("*.parquet")):
        rel = table.relative_to(a)
        other = b / rel
        if not other.exists():
            problems.append(f"missing in {b}: {rel}")
            continue
        x, y = pd.read_parquet(table), pd.read_parquet(other)
        n += 1
        try:
            pd.testing.assert_frame_equal(x[[c for c in x.columns if not timing_column(c)]],
                                          y[[c for c in y.columns if not timing_column(c)]], check_exact=True)
        except AssertionError as err:
            problems.append(f"differs: {rel}: {' '.join(str(err).split())[:300]}")
    return n, problems


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_a", type=Path)
    ap.add_argument("run_b", type=Path)
    args = ap.parse_args()
    n, problems = compare(args.run_a, args.run_b)
    for line in problems:
        print(line)
    print(f"{n} tables compared, {len(problems)} differ or are missing")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
