"""One table per study and drive: ``lost_motion.parquet``, one row per design.

Columns (units in names and in the Arrow field metadata): ``design_id``, the five
``*_mm`` parameters, ``phi_plus_arcmin`` and ``phi_minus_arcmin`` (null where unknown, e.g.
the paper gives only Φ), ``lost_motion_arcmin`` (null when the design failed) and
``status`` (``ok``, ``published`` or ``failed: <reason>``); further columns (solve times,
iterations…) are kept after these.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa

from hdwf import PARAMETER_COLUMNS
from hdwf.common.io import write_parquet

CORE_COLUMNS = ["design_id", *PARAMETER_COLUMNS, "phi_plus_arcmin", "phi_minus_arcmin",
                "lost_motion_arcmin", "status"]


def lost_motion_schema(extra: pd.DataFrame | None = None) -> pa.Schema:
    fields = [pa.field("design_id", pa.string(), nullable=False)]
    fields += [pa.field(c, pa.float64(), nullable=False) for c in PARAMETER_COLUMNS]
    fields += [pa.field(c, pa.float64()) for c in ("phi_plus_arcmin", "phi_minus_arcmin", "lost_motion_arcmin")]
    fields += [pa.field("status", pa.string(), nullable=False)]
    if extra is not None:
        for col in extra.columns:
            fields.append(pa.field(col, pa.Table.from_pandas(extra[[col]], preserve_index=False).schema.field(col).type))
    return pa.schema(fields)


def lost_motion_frame(df: pd.DataFrame) -> pd.DataFrame:
    """Order and type the columns; a design whose status is not ok/published gets a null Φ."""
    missing = [c for c in ("design_id", *PARAMETER_COLUMNS, "status") if c not in df.columns]
    if missing:
        raise ValueError(f"lost-motion rows lack column(s) {missing}")
    out = df.copy()
    for col in ("phi_plus_arcmin", "phi_minus_arcmin", "lost_motion_arcmin"):
        if col not in out.columns:
            out[col] = np.nan
        out[col] = out[col].astype("float64")
    failed = ~out["status"].isin(["ok", "published"])
    # A failed solve must never be read as a number downstream.
    out.loc[failed, ["phi_plus_arcmin", "phi_minus_arcmin", "lost_motion_arcmin"]] = np.nan
    extra = [c for c in out.columns if c not in CORE_COLUMNS]
    return out[CORE_COLUMNS + extra].sort_values("design_id").reset_index(drop=True)


def write_lost_motion(df: pd.DataFrame, path: str | Path, provenance: dict, meta: dict | None = None) -> Path:
    df = lost_motion_frame(df)
    extra = df[[c for c in df.columns if c not in CORE_COLUMNS]]
    return write_parquet(df, path, provenance=provenance, meta=meta,
                         schema=lost_motion_schema(extra if len(extra.columns) else None))


def read_lost_motion(path: str | Path) -> pd.DataFrame:
    return pd.read_parquet(path)
