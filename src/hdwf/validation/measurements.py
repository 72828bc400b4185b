"""Lost-motion measurements from a test bench: the documented file format and its checks.

Three forms (``docs/measurements.md``), chosen by the columns present:

* ``curve``: one row per recorded point, ``specimen_id, unit, d_mm, D_mm, Gr_mm, rFS_mm,
  rCS_mm, step, torque_Nm, twist_arcmin`` — the test 0 → +4 % T_N → 0 → −4 % T_N → 0 in
  ``step`` order;
* ``phi``: one row per specimen with ``phi_plus_arcmin, phi_minus_arcmin``;
* ``lost_motion``: one row per specimen with ``lost_motion_arcmin`` only (as the paper's tables).

An optional ``u_twist_arcmin`` (curve) or ``u_arcmin`` (phi, lost_motion) column gives the
standard uncertainty of the measured value. CSV or Parquet by extension. The loader never
writes to the file; it collects every problem it finds and raises one MeasurementError
listing them, each with file, row and field.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from hdwf import PARAMETER_COLUMNS, PARAMETERS, UNITS
from hdwf.common.errors import InputError
from hdwf.drive.geometry import unit_data

ID_COLUMNS = ["specimen_id", "unit", *PARAMETER_COLUMNS]
FORMS = {
    "curve": ["step", "torque_Nm", "twist_arcmin"],
    "phi": ["phi_plus_arcmin", "phi_minus_arcmin"],
    "lost_motion": ["lost_motion_arcmin"],
}
UNCERTAINTY_COLUMN = {"curve": "u_twist_arcmin", "phi": "u_arcmin", "lost_motion": "u_arcmin"}
# Columns that carry the right quantity in the wrong unit: named so the user knows what to convert.
_WRONG_UNITS = {
    "torque": ("torque_Nm", ["torque_kNm", "torque_Nmm", "torque_mNm", "torque_lbfin", "torque_ozin", "torque"]),
    "twist": ("twist_arcmin", ["twist_deg", "twist_rad", "twist_arcsec", "twist_mrad", "twist_urad", "twist"]),
    "lost_motion": ("lost_motion_arcmin", ["lost_motion_deg", "lost_motion_arcsec", "lost_motion_rad"]),
}
# Table 3 bounds of each drive (mm). The same numbers as data/paper/table3_bounds.csv, which
# ``hdwf.study.paper.table3_bounds(data_dir, unit)`` reads: kept here so that checking a
# measurement file or synthesising one needs no data directory (tests/validation/
# test_measurements.py checks that the two agree).
TABLE3_BOUNDS = {
    "hd42": {"d": (31.0, 31.016), "D": (41.984, 42.0), "Gr": (0.005, 0.02), "rFS": (0.0, 0.02), "rCS": (0.0, 0.02)},
    "hd120": {"d": (90.0, 90.022), "D": (119.978, 120.0), "Gr": (0.0, 0.055), "rFS": (0.025, 0.055),
              "rCS": (0.025, 0.055)},
}


def lost_motion_test_torque_Nm(unit: str) -> float:
    """The test torque of drive ``unit`` (``"hd42"`` or ``"hd120"``).

    Returns
    -------
    float
        4 % of T_N (N·m), from the drive table of ``hdwf.drive.geometry``.
    """
    return unit_data(unit).torque_Nmm / 1000.0


def supported_bounds(unit: str) -> dict[str, tuple[float, float]]:
    """Where the model is supported: one Table 3 span beyond its bounds on each side, and never
    at negative clearance or offsets (interference is outside the model's assumptions).

    Parameters
    ----------
    unit : str
        The drive.

    Returns
    -------
    dict
        ``{parameter: (low, high)}`` in mm, by parameter name (``"d"`` … ``"rCS"``).
    """
    out = {}
    for p, (lo, hi) in TABLE3_BOUNDS[unit].items():
        span = hi - lo
        lo2, hi2 = lo - span, hi + span
        if p in ("Gr", "rFS", "rCS"):
            lo2 = max(lo2, 0.0)
        out[p] = (lo2, hi2)
    return out


class MeasurementError(InputError):
    """Every problem of a measurement file, each naming file, row and field."""

    def __init__(self, file, problems: list[tuple]):
        self.problems = problems
        lines = [str(InputError(file, msg, row=row, field=field, value=value)) for row, field, value, msg in problems]
        shown = lines[:25] + ([f"... and {len(lines) - 25} more"] if len(lines) > 25 else [])
        super().__init__(file, f"{len(problems)} problem(s):\n  " + "\n  ".join(shown))


@dataclass
class Measurements:
    """A checked measurement file."""

    path: Path
    form: str                 # curve | phi | lost_motion
    data: pd.DataFrame        # the rows as read, with typed columns
    specimens: pd.DataFrame   # one row per specimen: ID_COLUMNS (+ phi/lost motion where given)

    @property
    def units(self) -> list[str]:
        """The drives of its specimens, sorted."""
        return sorted(self.specimens["unit"].unique())


def _read_raw(path: Path) -> pd.DataFrame:
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return pd.read_csv(path, dtype=str, keep_default_na=False, skipinitialspace=True)
    if suffix in (".parquet", ".pq"):
        return pd.read_parquet(path)
    raise InputError(path, f"unknown file type '{suffix}': measurement files are .csv or .parquet")


def _form_of(columns) -> str | None:
    for form, cols in FORMS.items():
        if all(c in columns for c in cols):
            return form
    return None


def load_measurements(path: str | Path) -> Measurements:
    """Read and check a measurement file.

    Parameters
    ----------
    path : str or Path
        A ``.csv`` or ``.parquet`` file in one of the documented forms.

    Returns
    -------
    Measurements
        The checked rows and one row per specimen.

    Raises
    ------
    InputError
        When the file is missing or of an unknown type.
    MeasurementError
        Listing every problem found, each with row and field.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(path, "file not found")
    raw = _read_raw(path)
    form, problems = _header_problems(list(raw.columns))
    if problems:
        raise MeasurementError(path, problems)
    if len(raw) == 0:
        raise MeasurementError(path, [(None, None, None, "no data rows")])
    data, problems = _typed_data(raw, form)
    problems += _value_problems(data, form)
    problems += _check_specimens(data, form)
    if problems:
        raise MeasurementError(path, sorted(problems, key=lambda p: (p[0] or 0)))
    specimens = _specimen_table(data, form)
    return Measurements(path=path, form=form, data=data, specimens=specimens)


def _header_problems(cols: list[str]) -> tuple[str | None, list[tuple]]:
    """The form the columns give, and what is wrong with them (wrong units, missing columns)."""
    problems = []
    for quantity, (right, wrongs) in _WRONG_UNITS.items():
        for w in wrongs:
            if w in cols and right not in cols:
                problems.append((None, w, None, f"wrong unit: give {quantity} as '{right}'"))
    form = _form_of(cols)
    if form is None:
        problems.append((None, "twist_arcmin", None,
                         "no measured quantity: need step, torque_Nm, twist_arcmin (curve), or phi_plus_arcmin, "
                         "phi_minus_arcmin, or lost_motion_arcmin; found " + ", ".join(cols)))
    for c in ID_COLUMNS:
        if c not in cols:
            problems.append((None, c, None, "missing column"))
    return form, problems


def _typed_data(raw: pd.DataFrame, form: str) -> tuple[pd.DataFrame, list[tuple]]:
    """The rows with typed columns, and every value that is not a number, an id or a drive."""
    problems = []
    numeric = list(PARAMETER_COLUMNS) + FORMS[form]
    ucol = UNCERTAINTY_COLUMN[form]
    if ucol in raw.columns:
        numeric.append(ucol)
    data = pd.DataFrame({"specimen_id": raw["specimen_id"].astype(str).str.strip(),
                         "unit": raw["unit"].astype(str).str.strip().str.lower().str.replace(" ", "")})
    for c in numeric:
        values = pd.to_numeric(raw[c], errors="coerce").astype(float)
        for i in np.flatnonzero(~np.isfinite(values.to_numpy())):
            problems.append((i + 1, c, raw[c].iloc[i], "not a finite number (empty, NaN or text)"))
        data[c] = values
    for i in np.flatnonzero((data["specimen_id"] == "").to_numpy()):
        problems.append((i + 1, "specimen_id", "", "empty specimen id"))
    for i in np.flatnonzero(~data["unit"].isin(UNITS).to_numpy()):
        problems.append((i + 1, "unit", raw["unit"].iloc[i], f"unknown drive; the model knows {list(UNITS)}"))
    return data, problems


def _value_problems(data: pd.DataFrame, form: str) -> list[tuple]:
    """Parameters outside the model's support and negative uncertainties."""
    problems = []
    for i, row in data.iterrows():
        if row["unit"] not in UNITS:
            continue
        for p, c in zip(PARAMETERS, PARAMETER_COLUMNS):
            lo, hi = supported_bounds(row["unit"])[p]
            v = row[c]
            if np.isfinite(v) and not lo - 1e-12 <= v <= hi + 1e-12:
                problems.append((i + 1, c, v, f"outside what the model supports for {row['unit']}: [{lo:g}, {hi:g}] mm"))
    ucol = UNCERTAINTY_COLUMN[form]
    if ucol in data:
        for i in np.flatnonzero((data[ucol] < 0).to_numpy()):
            problems.append((i + 1, ucol, data[ucol].iloc[i], "an uncertainty cannot be negative"))
    return problems


def _check_specimens(data: pd.DataFrame, form: str) -> list[tuple]:
    problems = []
    for sid, rows in data.groupby("specimen_id", sort=False):
        first = rows.index[0]
        for c in ["unit", *PARAMETER_COLUMNS]:
            differs = rows.index[rows[c].astype(str) != str(rows[c].iloc[0])]
            for i in differs:
                problems.append((i + 1, c, data.at[i, c], f"specimen '{sid}' changes {c} between rows "
                                                          f"(row {first + 1} has {rows[c].iloc[0]!r})"))
        if form != "curve":
            for i in rows.index[1:]:
                problems.append((i + 1, "specimen_id", sid, f"specimen '{sid}' appears twice; give one row per specimen"))
            continue
        steps = rows["step"]
        for i in rows.index[steps.duplicated().to_numpy()]:
            problems.append((i + 1, "step", data.at[i, "step"], f"duplicate step in specimen '{sid}'"))
        unit = rows["unit"].iloc[0]
        if unit in UNITS and np.isfinite(rows["torque_Nm"]).all():
            t = rows.sort_values("step")["torque_Nm"].to_numpy()
            test = lost_motion_test_torque_Nm(unit)
            if t.max() <= 0 or t.min() >= 0:
                problems.append((first + 1, "torque_Nm", None, f"specimen '{sid}' does not load in both directions "
                                                               "(the test is 0 → +4 % T_N → 0 → −4 % T_N → 0)"))
            big = np.abs(t) > 1.5 * test
            for i in rows.sort_values("step").index[big]:
                problems.append((i + 1, "torque_Nm", data.at[i, "torque_Nm"],
                                 f"beyond 1.5 × the test torque ±{test:g} N·m of {unit} (wrong unit?)"))
    return problems


def _specimen_table(data: pd.DataFrame, form: str) -> pd.DataFrame:
    spec = data.groupby("specimen_id", sort=False)[["unit", *PARAMETER_COLUMNS]].first().reset_index()
    if form == "phi":
        extra = data.groupby("specimen_id", sort=False)[FORMS["phi"]].first().reset_index()
        spec = spec.merge(extra, on="specimen_id")
        spec["lost_motion_arcmin"] = spec["phi_plus_arcmin"] + spec["phi_minus_arcmin"]
    elif form == "lost_motion":
        spec = spec.merge(data.groupby("specimen_id", sort=False)[["lost_motion_arcmin"]].first().reset_index(),
                          on="specimen_id")
    return spec
