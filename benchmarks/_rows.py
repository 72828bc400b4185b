"""Appending benchmark rows to a CSV without mixing column layouts."""

from __future__ import annotations

from pathlib import Path

import pandas as pd


def append_rows(path: Path, frame: pd.DataFrame) -> None:
    """Append ``frame`` to ``path`` (with a header if new); a file written with other columns
    (an older version of the benchmark) is refused rather than silently misaligned."""
    if path.exists():
        old = list(pd.read_csv(path, nrows=0).columns)
        if old != list(frame.columns):
            raise SystemExit(f"{path}: its columns {old} differ from this run's {list(frame.columns)}; "
                             "write to a new --out")
    frame.to_csv(path, mode="a", header=not path.exists(), index=False)
