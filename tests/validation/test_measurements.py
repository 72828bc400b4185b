"""Measurement files: the three forms load; every kind of problem is named with file, row, field."""

import hashlib

import numpy as np
import pandas as pd
import pytest

from hdwf.study.paper import table3_bounds
from hdwf.validation.measurements import TABLE3_BOUNDS, MeasurementError, load_measurements

from conftest import DATA, write_table

PARAMS = {"d_mm": 31.008, "D_mm": 41.992, "Gr_mm": 0.012, "rFS_mm": 0.01, "rCS_mm": 0.01}
TORQUES = [0.0, 0.48, 0.96, 0.48, 0.0, -0.48, -0.96, -0.48, 0.0]


def _curve(specimens=("S1", "S2")):
    rows = []
    for s in specimens:
        for k, t in enumerate(TORQUES):
            rows.append({"specimen_id": s, "unit": "hd42", **PARAMS, "step": k, "torque_Nm": t,
                         "twist_arcmin": 0.3 * np.sign(t) + 0.1 * t})
    return pd.DataFrame(rows)



@pytest.mark.parametrize("name", ["m.csv", "m.parquet"])
def test_curve_form_loads(tmp_path, name):
    m = load_measurements(write_table(_curve(), tmp_path, name))
    assert m.form == "curve" and len(m.specimens) == 2 and m.units == ["hd42"]


def test_phi_and_lost_motion_forms(tmp_path):
    df = pd.DataFrame([{"specimen_id": "A", "unit": "HD42", **PARAMS, "phi_plus_arcmin": 0.2, "phi_minus_arcmin": 0.25}])
    m = load_measurements(write_table(df, tmp_path))
    assert m.form == "phi" and m.specimens.loc[0, "lost_motion_arcmin"] == pytest.approx(0.45)
    df = pd.DataFrame([{"specimen_id": "A", "unit": "hd120", "d_mm": 90.01, "D_mm": 119.99, "Gr_mm": 0.02,
                        "rFS_mm": 0.04, "rCS_mm": 0.04, "lost_motion_arcmin": 1.2}])
    assert load_measurements(write_table(df, tmp_path)).form == "lost_motion"


def _problems(path):
    with pytest.raises(MeasurementError) as exc:
        load_measurements(path)
    return exc.value, str(exc.value)


def test_every_problem_is_reported_and_the_file_is_untouched(tmp_path):
    df = _curve()
    df.loc[3, "twist_arcmin"] = np.nan          # row 4: NaN
    df.loc[5, "step"] = 4                        # row 6: duplicate step of S1
    df.loc[11, "unit"] = "hd50"                  # row 12: unknown drive
    df.loc[13, "rFS_mm"] = 0.5                   # row 14: outside the model
    path = write_table(df, tmp_path)
    before = hashlib.sha256(path.read_bytes()).hexdigest()
    err, msg = _problems(path)
    assert "m.csv, row 4, field 'twist_arcmin'" in msg
    assert "m.csv, row 6, field 'step', value 4:" in msg and "duplicate step" in msg   # 4, not 4.0
    assert "m.csv, row 12, field 'unit', value 'hd50'" in msg and "unknown drive" in msg
    assert "m.csv, row 14, field 'rFS_mm', value 0.5" in msg and "outside what the model supports" in msg
    assert hashlib.sha256(path.read_bytes()).hexdigest() == before


def test_missing_column_and_wrong_unit(tmp_path):
    df = _curve().rename(columns={"twist_arcmin": "twist_deg"}).drop(columns="Gr_mm")
    _, msg = _problems(write_table(df, tmp_path))
    assert "field 'twist_deg'" in msg and "wrong unit" in msg and "twist_arcmin" in msg
    assert "field 'Gr_mm'" in msg and "missing column" in msg


@pytest.mark.parametrize("given, needed", [("rFS_um", "rFS_mm"), ("d_in", "d_mm"), ("D", "D_mm"), ("gr", "Gr_mm")])
def test_a_parameter_in_another_unit_is_named_not_reported_missing(tmp_path, given, needed):
    """'rFS_um' is r_FS in micrometres: the problem names the column that is there and what to give,
    once, and says nothing of a missing 'rFS_mm' (d and D differ only in case, so 'D' is D's)."""
    df = _curve().rename(columns={needed: given})
    error, msg = _problems(write_table(df, tmp_path))
    assert f"field '{given}'" in msg and f"give {needed.removesuffix('_mm')} in mm as '{needed}'" in msg
    assert "missing column" not in msg and len(error.problems) == 1, msg


def test_a_note_column_is_not_taken_for_a_parameter_in_another_unit(tmp_path):
    """'gr_note' shares Gr's stem but is no unit: with Gr_mm missing the file is refused for that, and
    the note is not named as Gr given wrongly."""
    df = _curve().rename(columns={"Gr_mm": "gr_note"})
    error, msg = _problems(write_table(df, tmp_path))
    assert "field 'Gr_mm'" in msg and "missing column" in msg and "gr_note" not in msg, msg


def test_a_semicolon_separated_file_is_one_problem_naming_the_separator(tmp_path):
    """European spreadsheets save CSV with ';': one column to the reader. One problem says so, not ten
    missing columns."""
    path = tmp_path / "m.csv"
    _curve().to_csv(path, sep=";", index=False)
    error, msg = _problems(path)
    assert len(error.problems) == 1 and "separated by ';', not commas" in msg, msg


def test_torque_in_wrong_unit_is_caught_by_size(tmp_path):
    df = _curve()
    df["torque_Nm"] *= 1000  # N·mm given as N·m
    _, msg = _problems(write_table(df, tmp_path))
    assert "row 3, field 'torque_Nm', value 960.0" in msg and "1.5 × the test torque" in msg


def test_inconsistent_specimen_parameters(tmp_path):
    df = _curve()
    df.loc[2, "d_mm"] = 31.01
    _, msg = _problems(write_table(df, tmp_path))
    assert "row 3, field 'd_mm'" in msg and "changes d_mm" in msg


def test_unknown_extension(tmp_path):
    path = tmp_path / "m.xlsx"
    path.write_text("x")
    with pytest.raises(Exception, match="m.xlsx.*csv or .parquet"):
        load_measurements(path)


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_table3_bounds_are_the_papers(unit):
    """The loader's copy of Table 3 (no data directory needed) is data/paper/table3_bounds.csv."""
    assert TABLE3_BOUNDS[unit] == table3_bounds(DATA, unit)
