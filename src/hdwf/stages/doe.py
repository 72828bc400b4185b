"""Stage of ``workflow/rules/doe.smk``: our optimal Latin hypercube of one drive as Parquet."""

from __future__ import annotations

from dataclasses import asdict

import pandas as pd

from hdwf.common.io import write_parquet
from hdwf.study.doe import optimal_lhs


def doe_stage(bounds: dict[str, tuple[float, float]], n: int, seed: int, optimization: str,
              out, provenance: dict, unit: str) -> pd.DataFrame:
    """Write the optimal LHS of one drive as Parquet; the criteria go into the file metadata."""
    df, criteria = optimal_lhs(bounds, n, seed, optimization, prefix=f"{unit}-lhs")
    write_parquet(df, out, provenance=provenance,
                  meta={"unit": unit, "seed": seed, "optimization": optimization, "n": n,
                        "bounds_mm": bounds, "space_filling": asdict(criteria)})
    return df
