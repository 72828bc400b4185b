"""The seed paper's tables (``data/paper/``): its drives, bounds, FEA design points and statistics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from hdwf import PARAMETER_COLUMNS, PARAMETERS
from hdwf.common.errors import InputError
from hdwf.common.io import read_table

FEA_TABLES = {"hd42": "table4_hd42_fea.csv", "hd120": "table5_hd120_fea.csv"}
# Every file of the paper's data folder this module reads.
PAPER_TABLES = ("table1_drives.csv", "table2_bearings.csv", "table3_bounds.csv", *FEA_TABLES.values(),
                "published_statistics.csv")
_FEA_COLUMNS = {"set": "int", **{c: "float" for c in PARAMETER_COLUMNS}, "lost_motion_arcmin": "float"}


def load_fea_designs(data_dir: str | Path, unit: str) -> pd.DataFrame:
    """The paper's 27 design points of one drive with its FEA lost motion Φ.

    Returns columns ``design_id`` (``paper-01`` …), the five ``*_mm`` parameters and
    ``lost_motion_arcmin``.
    """
    if unit not in FEA_TABLES:
        raise InputError(Path(data_dir), f"unknown drive '{unit}'; known: {sorted(FEA_TABLES)}", field="unit")
    path = Path(data_dir) / FEA_TABLES[unit]
    df = read_table(path, _FEA_COLUMNS)
    if df["set"].duplicated().any():
        i = int(np.argmax(df["set"].duplicated().to_numpy()))
        raise InputError(path, "duplicate design set number", row=i + 1, field="set", value=int(df["set"][i]))
    negative = df["lost_motion_arcmin"] < 0
    if negative.any():
        i = int(np.argmax(negative.to_numpy()))
        raise InputError(path, "lost motion cannot be negative", row=i + 1, field="lost_motion_arcmin",
                         value=float(df["lost_motion_arcmin"][i]))
    df = df.sort_values("set").reset_index(drop=True)
    df.insert(0, "design_id", [f"paper-{s:02d}" for s in df["set"]])
    return df.drop(columns="set")


def load_bounds(data_dir: str | Path, unit: str) -> pd.DataFrame:
    """Table 3 for one drive: index ``nominal/minimal/maximal``, columns the five parameters (mm)."""
    path = Path(data_dir) / "table3_bounds.csv"
    df = read_table(path, {"unit": "str", "limit": "str", **{c: "float" for c in PARAMETER_COLUMNS}})
    sub = df[df["unit"] == unit].set_index("limit")[list(PARAMETER_COLUMNS)]
    for limit in ("nominal", "minimal", "maximal"):
        if limit not in sub.index:
            raise InputError(path, f"no '{limit}' row for drive '{unit}'", field="limit")
    lo, hi = sub.loc["minimal"].to_numpy(), sub.loc["maximal"].to_numpy()
    if np.any(hi <= lo):
        j = int(np.argmax(hi <= lo))
        raise InputError(path, f"maximal must exceed minimal for drive '{unit}'", field=PARAMETER_COLUMNS[j],
                         value=float(hi[j]))
    return sub


def table3_bounds(data_dir: str | Path, unit: str) -> dict[str, tuple[float, float]]:
    sub = load_bounds(data_dir, unit)
    return {p: (float(sub.loc["minimal", c]), float(sub.loc["maximal", c])) for p, c in zip(PARAMETERS, PARAMETER_COLUMNS)}


def load_drives(data_dir: str | Path) -> pd.DataFrame:
    path = Path(data_dir) / "table1_drives.csv"
    df = read_table(path, {"unit": "str", "name": "str", "z_FS": "int", "z_CS": "int", "ratio": "float",
                           "n1_rpm": "float", "P1_W": "float", "T_N_Nm": "float", "T_test_published_Nm": "float"})
    return df.set_index("unit")


def load_bearings(data_dir: str | Path) -> pd.DataFrame:
    path = Path(data_dir) / "table2_bearings.csv"
    df = read_table(path, {"unit": "str", "bearing_type": "str", "d_mm": "float", "d1_max_mm": "float",
                           "D1_min_mm": "float", "D_mm": "float", "B_mm": "float", "O_min_mm": "float",
                           "O_max_mm": "float"})
    return df.set_index("unit")


def load_published(data_dir: str | Path) -> pd.DataFrame:
    """The statistics the paper states in its text (Spearman ρ, surrogate R², Sobol indices)."""
    path = Path(data_dir) / "published_statistics.csv"
    df = read_table(path, {"unit": "str", "statistic": "str", "value": "float"})
    df["parameter"] = df["parameter"].fillna("").astype(str)
    return df


def paper_measurements(data_dir: str | Path, unit: str) -> pd.DataFrame:
    """The paper's FEA results (Tables 4/5) in the documented measurement format
    (``lost_motion`` form, ``docs/measurements.md``): our 2D model held against their 3D one."""
    df = load_fea_designs(data_dir, unit)
    out = df.rename(columns={"design_id": "specimen_id"})
    out.insert(1, "unit", unit)
    return out[["specimen_id", "unit", *PARAMETER_COLUMNS, "lost_motion_arcmin"]]
