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
listing them, each with file, row and field (the list is in ``docs/measurements.md``, "What is
checked"). A file that cannot be read at all (missing, empty, not text, not Parquet) is one
MeasurementError saying why, never a parser's traceback.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from hdwf import PARAMETER_COLUMNS, PARAMETERS, UNITS
from hdwf.common.errors import InputError
from hdwf.drive.geometry import unit_data
from hdwf.validation.measurement_header import FORMS, UNCERTAINTY_COLUMN, header_problems

# The largest reading the loader believes (arcmin): Φ, φ, φ′, |twist| and a stated uncertainty.
# A harmonic drive's lost motion is about 0.1-10 arcmin (the paper's Tables 4 and 5: 0.18-2.5;
# the shipped demo's dead band about 9); 600 arcmin (10°) is far beyond any drive whose teeth
# still mesh, so a larger value is a unit or typing error (e.g. 1e9), not a measurement.
READING_LIMIT_ARCMIN = 600.0
# Quantities that are magnitudes: Φ is the width of the play, φ the twist at +4 % T_N (positive
# by the sign convention), φ′ the magnitude of the twist at −4 % T_N.
_NON_NEGATIVE = {
    "lost_motion_arcmin": "a lost motion is the width of the play",
    "phi_plus_arcmin": "φ is the twist at +4 % T_N, positive by the sign convention",
    "phi_minus_arcmin": "φ′ is the magnitude of the twist at −4 % T_N",
}
# A curve's twist must rise with torque. It is refused as a flipped sign only when the least-squares
# slope of twist on torque is this many standard errors below zero: a specimen whose play is lost in
# the noise can tilt either way by chance (one in a few hundred at 3), a flipped sign tilts by 7 or
# more (the shipped demo's curves: +7 to +9).
SIGN_TEST_STANDARD_ERRORS = 3.0
# A campaign names files after its specimens (hdwf.stages.validation): ids must be safe file names.
SPECIMEN_ID_PATTERN = r"[A-Za-z0-9_.\-]+"
# How much of a file is looked at to tell text from binary before parsing it.
_SNIFF_BYTES = 65536
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
        self.lines = lines  # one message per problem, all of them (the message shows the first 25)
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


def _unreadable(path: Path, why: str) -> MeasurementError:
    return MeasurementError(path, [(None, None, None, why)])


def _read_raw(path: Path) -> pd.DataFrame:
    """The file's table, as text (CSV) or as stored (Parquet); a file that cannot be read is one
    MeasurementError saying why."""
    try:
        with path.open("rb") as fh:
            head = fh.read(_SNIFF_BYTES)
    except OSError as exc:  # missing, a directory, no permission: the system's words
        raise _unreadable(path, f"cannot read the measurement file: {exc.strerror or exc}") from None
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".parquet", ".pq"):
        raise _unreadable(path, f"unknown file type '{suffix}': measurement files are .csv or .parquet")
    if not head:
        raise _unreadable(path, "cannot read the measurement file: empty file")
    return _read_csv(path, head) if suffix == ".csv" else _read_parquet(path)


def _read_csv(path: Path, head: bytes) -> pd.DataFrame:
    # NUL never occurs in text; UTF-8 that decodes is not enough (binary can be valid ASCII)
    if b"\x00" in head:
        raise _unreadable(path, "cannot read the measurement file: not a text CSV file (it holds NUL bytes)")
    read = dict(dtype=str, keep_default_na=False, skipinitialspace=True, encoding="utf-8")
    try:
        data = pd.read_csv(path, **read)
        header = pd.read_csv(path, header=None, nrows=1, **read).iloc[0].tolist()
    except UnicodeDecodeError:
        raise _unreadable(path, "cannot read the measurement file: not a text CSV file (not UTF-8; save it "
                                "as UTF-8 text)") from None
    except pd.errors.EmptyDataError:
        raise _unreadable(path, "cannot read the measurement file: empty file (no header line)") from None
    except pd.errors.ParserError as exc:
        raise _unreadable(path, f"cannot read the measurement file: malformed CSV: {exc}".strip()) from None
    _refuse_repeated_columns(path, header)
    return data


def _refuse_repeated_columns(path: Path, names: list[str]) -> None:
    # pandas renames a repeated CSV column ('twist_arcmin.1') and reads only the first: two columns
    # of one name are two readings, and which one counts would be a guess
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise MeasurementError(path, [(None, name, None, f"the header names this column {names.count(name)} times: "
                                                         "keep one") for name in twice])


def _read_parquet(path: Path) -> pd.DataFrame:
    unreadable = (OSError, ValueError, pa.ArrowException)
    try:
        names = pq.read_schema(path).names
    except unreadable as exc:
        raise _not_parquet(path, exc) from None
    _refuse_repeated_columns(path, names)
    try:
        return pd.read_parquet(path)
    except unreadable as exc:
        raise _not_parquet(path, exc) from None


def _not_parquet(path: Path, exc: Exception) -> MeasurementError:
    # pyarrow repeats the path ("Could not open Parquet input source '...': why"): keep the why
    why = str(exc).rsplit("': ", 1)[-1].strip()
    return _unreadable(path, f"cannot read the measurement file: not a Parquet file ({why})")


def load_measurements(path: str | Path, unit: str | None = None) -> Measurements:
    """Read and check a measurement file.

    Parameters
    ----------
    path : str or Path
        A ``.csv`` or ``.parquet`` file in one of the documented forms.
    unit : str, optional
        The drive the file is for (``"hd42"`` or ``"hd120"``), as a campaign has it: every
        specimen must be of this drive and have an id that can name a file.

    Returns
    -------
    Measurements
        The checked rows and one row per specimen.

    Raises
    ------
    MeasurementError
        Listing every problem found, each with file and where known row, field and value; a file
        that cannot be read (missing, empty, not text, not Parquet, unknown type) is one problem.
    """
    path = Path(path)
    if unit is not None and unit not in UNITS:
        raise ValueError(f"unknown drive {unit!r}; the model knows {list(UNITS)}")
    raw = _read_raw(path)
    form, problems = header_problems(list(raw.columns))
    if problems:
        raise MeasurementError(path, problems)
    if len(raw) == 0:
        raise MeasurementError(path, [(None, None, None, "no data rows")])
    data, problems = _typed_data(raw, form)
    problems += _value_problems(data, form)
    problems += _check_specimens(data, form)
    if unit is not None:
        problems += _drive_problems(data, unit)
    if problems:
        raise MeasurementError(path, sorted(problems, key=lambda p: (p[0] or 0)))
    specimens = _specimen_table(data, form)
    return Measurements(path=path, form=form, data=data, specimens=specimens)


def _typed_data(raw: pd.DataFrame, form: str) -> tuple[pd.DataFrame, list[tuple]]:
    """The rows with typed columns, and every value that is not a number, an id or a drive."""
    problems = []
    numeric = list(PARAMETER_COLUMNS) + FORMS[form]
    ucol = UNCERTAINTY_COLUMN[form]
    if ucol in raw.columns:
        numeric.append(ucol)
    # a null id or drive (a Parquet null) is an empty one, not the text "None" or "nan"
    data = pd.DataFrame({"specimen_id": raw["specimen_id"].astype(str).str.strip().where(raw["specimen_id"].notna(), ""),
                         "unit": raw["unit"].astype(str).str.strip().str.lower().str.replace(" ", "")
                                 .where(raw["unit"].notna(), "")})
    for c in numeric:
        if raw[c].dtype.kind in "bmM":   # booleans and times would read as numbers
            problems.append((1, c, str(raw[c].dtype), f"a column of {raw[c].dtype}, not numbers"))
            data[c] = np.nan
            continue
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
    """Parameters outside the model's support, implausible readings and uncertainties."""
    return _parameter_problems(data) + _reading_problems(data, form) + _uncertainty_problems(data, form)


def _parameter_problems(data: pd.DataFrame) -> list[tuple]:
    problems = []
    for i, row in data.iterrows():
        if row["unit"] not in UNITS:
            continue
        for p, c in zip(PARAMETERS, PARAMETER_COLUMNS):
            lo, hi = supported_bounds(row["unit"])[p]
            v = row[c]
            if np.isfinite(v) and not lo - 1e-12 <= v <= hi + 1e-12:
                problems.append((i + 1, c, v, f"outside what the model supports for {row['unit']}: [{lo:g}, {hi:g}] mm"))
    return problems


def _rows_where(data: pd.DataFrame, c: str, bad: np.ndarray, msg: str) -> list[tuple]:
    return [(i + 1, c, data[c].iloc[i], msg) for i in np.flatnonzero(bad)]


def _too_large(what: str = "") -> str:
    return (f"implausibly large{what}: beyond {READING_LIMIT_ARCMIN:g} arcmin (10°), where a harmonic drive's "
            "lost motion is 0.1-10 arcmin (a unit or typing error?)")


def _reading_problems(data: pd.DataFrame, form: str) -> list[tuple]:
    """Non-integer steps, negative magnitudes and readings beyond ``READING_LIMIT_ARCMIN``."""
    problems = []
    for c in FORMS[form]:
        v = data[c].to_numpy(float)
        finite = np.isfinite(v)
        if c == "step":
            problems += _rows_where(data, c, finite & (v != np.round(v)),
                                    "a step is a whole number: the order of the point in the test")
        elif c in _NON_NEGATIVE:
            problems += _rows_where(data, c, finite & (v < 0), f"cannot be negative: {_NON_NEGATIVE[c]}")
            problems += _rows_where(data, c, finite & (v > READING_LIMIT_ARCMIN), _too_large())
        elif c == "twist_arcmin":
            problems += _rows_where(data, c, finite & (np.abs(v) > READING_LIMIT_ARCMIN), _too_large(" |twist|"))
        # torque_Nm has a bound of its own, the drive's test torque (_curve_problems)
    return problems


def _uncertainty_problems(data: pd.DataFrame, form: str) -> list[tuple]:
    ucol = UNCERTAINTY_COLUMN[form]
    if ucol not in data:
        return []
    u = data[ucol].to_numpy(float)
    return (_rows_where(data, ucol, u < 0, "an uncertainty cannot be negative")
            + _rows_where(data, ucol, u == 0, "zero uncertainty: every reading has a non-zero uncertainty; "
                                              "give the bench's standard uncertainty, or leave the column out")
            + _rows_where(data, ucol, np.isfinite(u) & (u > READING_LIMIT_ARCMIN), _too_large(" uncertainty")))


def _check_specimens(data: pd.DataFrame, form: str) -> list[tuple]:
    """Per specimen: the same drive and parameters on every row; one row each (phi,
    lost_motion) or a well-formed curve."""
    problems = []
    for sid, rows in data.groupby("specimen_id", sort=False):
        for c in ["unit", *PARAMETER_COLUMNS]:
            # empty and NaN cells are reported already: compare the given values only
            given = rows[c][rows[c].notna() & (rows[c].astype(str) != "")]
            if given.empty:
                continue
            ref = given.iloc[0]
            ref = ref.item() if hasattr(ref, "item") else ref
            for i in given.index[given.astype(str) != str(ref)]:
                problems.append((i + 1, c, data.at[i, c], f"specimen '{sid}' changes {c} between rows "
                                                          f"(row {given.index[0] + 1} has {ref!r})"))
        if form == "curve":
            problems += _curve_problems(data, sid, rows)
        else:
            for i in rows.index[1:]:
                problems.append((i + 1, "specimen_id", sid, f"specimen '{sid}' appears twice; give one row per specimen"))
    return problems


def _curve_problems(data: pd.DataFrame, sid: str, rows: pd.DataFrame) -> list[tuple]:
    """Duplicate steps, a test that does not load both ways, torque beyond the test, a flipped sign."""
    problems = []
    first = rows.index[0]
    for i in rows.index[rows["step"].duplicated().to_numpy()]:
        step = data.at[i, "step"]
        step = int(step) if float(step).is_integer() else step   # 3 as the file has it, not 3.0
        problems.append((i + 1, "step", step, f"duplicate step in specimen '{sid}'"))
    unit = rows["unit"].iloc[0]
    if unit not in UNITS or not np.isfinite(rows["torque_Nm"]).all():
        return problems
    t = rows.sort_values("step")["torque_Nm"].to_numpy()
    test = lost_motion_test_torque_Nm(unit)
    if t.max() <= 0 or t.min() >= 0:
        problems.append((first + 1, "torque_Nm", None, f"specimen '{sid}' does not load in both directions "
                                                       "(the test is 0 → +4 % T_N → 0 → −4 % T_N → 0)"))
    big = np.abs(t) > 1.5 * test
    for i in rows.sort_values("step").index[big]:
        problems.append((i + 1, "torque_Nm", data.at[i, "torque_Nm"],
                         f"beyond 1.5 × the test torque ±{test:g} N·m of {unit} (wrong unit?)"))
    return problems + _sign_problems(sid, rows)


def _sign_problems(sid: str, rows: pd.DataFrame) -> list[tuple]:
    """Twist that falls as torque rises: the least-squares slope of twist on torque over the
    specimen's points, ``SIGN_TEST_STANDARD_ERRORS`` standard errors below zero."""
    t, w = rows["torque_Nm"].to_numpy(float), rows["twist_arcmin"].to_numpy(float)
    if not (np.isfinite(t).all() and np.isfinite(w).all()):
        return []
    x = t - t.mean()
    sxx = float(x @ x)
    if sxx == 0.0:  # one torque only: "does not load in both directions" says it
        return []
    slope = float(x @ (w - w.mean())) / sxx
    resid = w - w.mean() - slope * x
    se = float(np.sqrt(resid @ resid / (len(t) - 2) / sxx)) if len(t) > 2 else 0.0
    if slope + SIGN_TEST_STANDARD_ERRORS * se >= 0:
        return []
    how = f"{-slope / se:.1f} standard errors below zero" if se > 0 else "exactly"
    return [(rows.index[0] + 1, "torque_Nm", None,
             f"specimen '{sid}': twist falls as torque rises (least-squares slope {slope:.3g} arcmin/N·m, {how}); "
             "positive torque gives positive twist, so a sign is flipped (of torque_Nm or of twist_arcmin)")]


def _drive_problems(data: pd.DataFrame, unit: str) -> list[tuple]:
    """What a campaign for ``unit`` needs: every specimen of that drive, ids that can name a file."""
    problems, by_folded_case = [], {}
    for sid, rows in data.groupby("specimen_id", sort=False):
        first = rows.index[0]
        # ids outside the pattern are refused below; within it (ASCII) case is all that can differ
        other, other_row = (by_folded_case.setdefault(sid.lower(), (sid, first))
                            if re.fullmatch(SPECIMEN_ID_PATTERN, sid) else (sid, first))
        if other != sid:
            problems.append((first + 1, "specimen_id", sid, f"differs from specimen '{other}' (row {other_row + 1}) "
                                                            "only in case; a campaign names files after ids, and macOS "
                                                            "and Windows file systems do not tell them apart"))
        if rows["unit"].iloc[0] in UNITS and rows["unit"].iloc[0] != unit:  # an unknown drive is named already
            problems.append((first + 1, "unit", rows["unit"].iloc[0], f"specimen '{sid}' is not of {unit}, "
                                                                      "the drive these measurements are for"))
        if sid and not re.fullmatch(SPECIMEN_ID_PATTERN, sid):
            problems.append((first + 1, "specimen_id", sid, "specimen ids may use letters, digits, '_', '.' and '-' "
                                                            "only (a campaign names files after them)"))
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


def schedule_problems(meas: Measurements, steps_per_ramp: int) -> list[tuple]:
    """Curve points beyond the campaign model's test, found before any solve.

    A curve point is compared with the model at its measured torque (``observations.predict``):
    any step numbering, a test run −T first or a curve logged at its own torques meets the model
    where it was measured. The model's test goes to ± the test torque in ``steps_per_ramp``
    steps per ramp, so a measured torque more than a quarter of a load step beyond it would be
    compared with an extrapolation; those points are refused.

    Parameters
    ----------
    meas : Measurements
        A checked file (``load_measurements``); only the curve form has torques.
    steps_per_ramp : int
        The campaign's load steps per ramp.

    Returns
    -------
    list of tuple
        ``(row, field, value, message)`` per problem, as ``MeasurementError`` takes them.
    """
    if meas.form != "curve":
        return []
    d = meas.data
    torque = d["torque_Nm"].to_numpy(float)
    test = np.array([lost_motion_test_torque_Nm(u) for u in d["unit"]])
    beyond = np.abs(torque) > test * (1.0 + 0.25 / steps_per_ramp)
    return [(i + 1, "torque_Nm", float(torque[i]),
             f"beyond the campaign model's test torque ±{test[i]:.4g} N·m (by more than a quarter of a load step "
             f"at steps_per_ramp {steps_per_ramp}); the model is not extrapolated: drop the point or check the unit")
            for i in np.flatnonzero(beyond)]
