"""Bad measurement files are refused with file, row, field and value, never a traceback
(issue 16): implausible readings, non-integer steps, unreadable files, zero or negative
uncertainties, a flipped sign convention, and the checks of a campaign for one drive."""

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from hdwf.study.paper import paper_measurements
from hdwf.validation.measurements import (READING_LIMIT_ARCMIN, MeasurementError, load_measurements,
                                         schedule_problems)

from conftest import DATA, ROOT, write_table

SHIPPED = ROOT / "data" / "validation"
PARAMS = {"d_mm": 31.008, "D_mm": 41.992, "Gr_mm": 0.012, "rFS_mm": 0.01, "rCS_mm": 0.01}
TORQUES = [0.0, 0.48, 0.96, 0.48, 0.0, -0.48, -0.96, -0.48, 0.0]


def _curve(specimens=("S1", "S2")) -> pd.DataFrame:
    """Curves of 9 points each (rows 1-9 are S1, 10-18 S2), with 0.02 arcmin uncertainty."""
    rows = []
    for s in specimens:
        for k, t in enumerate(TORQUES):
            rows.append({"specimen_id": s, "unit": "hd42", **PARAMS, "step": float(k), "torque_Nm": t,
                         "twist_arcmin": 0.3 * np.sign(t) + 0.1 * t, "u_twist_arcmin": 0.02})
    return pd.DataFrame(rows)


def _phi() -> pd.DataFrame:
    return pd.DataFrame([{"specimen_id": s, "unit": "hd42", **PARAMS, "phi_plus_arcmin": 0.2,
                          "phi_minus_arcmin": 0.25, "u_arcmin": 0.02} for s in ("A", "B")])


def _lost_motion() -> pd.DataFrame:
    return pd.DataFrame([{"specimen_id": s, "unit": "hd42", **PARAMS, "lost_motion_arcmin": 0.45, "u_arcmin": 0.02}
                         for s in ("A", "B")])


FORMS = {"curve": _curve, "phi": _phi, "lost_motion": _lost_motion}



def _refused(path, **kw) -> list[str]:
    with pytest.raises(MeasurementError) as exc:
        load_measurements(path, **kw)
    # no parser's exception chained on (a traceback would show it)
    assert exc.value.__cause__ is None and (exc.value.__context__ is None or exc.value.__suppress_context__)
    return exc.value.lines


def test_the_shipped_files_still_load():
    """The demo and the paper's tables, as shipped and as `hdwf paper-measurements` writes them."""
    demo = load_measurements(SHIPPED / "demo_hd42.csv", unit="hd42")
    assert (demo.form, len(demo.specimens), len(demo.data)) == ("curve", 16, 336)
    for unit in ("hd42", "hd120"):
        assert len(load_measurements(SHIPPED / f"paper_{unit}.csv", unit=unit).specimens) == 27


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_the_papers_tables_load(tmp_path, unit):
    path = write_table(paper_measurements(DATA, unit), tmp_path, f"paper_{unit}.csv")
    m = load_measurements(path, unit=unit)
    assert m.form == "lost_motion" and len(m.specimens) == 27


# (form, row (1-based), column, bad value, what the message says); cases 1, 2 and 4 of the issue
BAD_VALUES = [
    ("lost_motion", 2, "lost_motion_arcmin", -0.3, "cannot be negative: a lost motion is the width of the play"),
    ("lost_motion", 1, "lost_motion_arcmin", 1e9, "implausibly large: beyond 600 arcmin"),
    ("phi", 1, "phi_plus_arcmin", -0.2, "cannot be negative: φ is the twist at +4 % T_N"),
    ("phi", 2, "phi_minus_arcmin", -0.1, "cannot be negative: φ′ is the magnitude"),
    ("phi", 1, "phi_plus_arcmin", 1e9, "implausibly large: beyond 600 arcmin"),
    ("phi", 2, "phi_minus_arcmin", 700.0, "implausibly large: beyond 600 arcmin"),
    ("curve", 3, "twist_arcmin", 1e9, "implausibly large |twist|: beyond 600 arcmin"),
    ("curve", 16, "twist_arcmin", -700.0, "implausibly large |twist|: beyond 600 arcmin"),
    ("curve", 5, "step", 4.5, "a step is a whole number"),
    ("curve", 4, "u_twist_arcmin", -0.01, "an uncertainty cannot be negative"),
    ("curve", 7, "u_twist_arcmin", 0.0, "zero uncertainty: every reading has a non-zero uncertainty"),
    ("curve", 8, "u_twist_arcmin", 1e4, "implausibly large uncertainty: beyond 600 arcmin"),
    ("phi", 2, "u_arcmin", 0.0, "zero uncertainty: every reading has a non-zero uncertainty"),
    ("lost_motion", 1, "u_arcmin", -1.0, "an uncertainty cannot be negative"),
]


@pytest.mark.parametrize("name", ["m.csv", "m.parquet"])
@pytest.mark.parametrize("form, row, column, value, says", BAD_VALUES,
                         ids=[f"{f}-{c}={v:g}" for f, _, c, v, _ in BAD_VALUES])
def test_an_implausible_value_is_refused_with_row_field_and_value(tmp_path, name, form, row, column, value, says):
    df = FORMS[form]()
    df.loc[row - 1, column] = value
    lines = _refused(write_table(df, tmp_path, name))
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"{tmp_path / name}, row {row}, field '{column}', value {value!r}: "), lines
    assert says in lines[0]


@pytest.mark.parametrize("form, column, value", [("lost_motion", "lost_motion_arcmin", READING_LIMIT_ARCMIN),
                                                 ("lost_motion", "lost_motion_arcmin", 0.0),
                                                 ("phi", "phi_minus_arcmin", 0.0),
                                                 ("curve", "twist_arcmin", -READING_LIMIT_ARCMIN)])
def test_values_at_the_bounds_load(tmp_path, form, column, value):
    df = FORMS[form]()
    df.loc[0, column] = value
    assert len(load_measurements(write_table(df, tmp_path)).specimens) == 2


def _holding(content: bytes):
    """Make a file holding ``content``."""
    def make(path):
        path.write_bytes(content)
        return path
    return make


RANDOM = np.random.default_rng(0).bytes(512)
# (file name, how to make it, what the one message says after "FILE: "); case 3 of the issue
UNREADABLE = [
    ("empty.csv", _holding(b""), "cannot read the measurement file: empty file"),
    ("empty.parquet", _holding(b""), "cannot read the measurement file: empty file"),
    ("blank.csv", _holding(b"\n\n"), "cannot read the measurement file: empty file (no header line)"),
    ("garbage.parquet", _holding(RANDOM), "cannot read the measurement file: not a Parquet file (Parquet magic bytes "),
    ("text.parquet", _holding(b"specimen_id,unit\nA,hd42\n"), "cannot read the measurement file: not a Parquet file ("),
    ("binary.csv", _holding(RANDOM), "cannot read the measurement file: not a text CSV file (it holds NUL bytes)"),
    ("latin1.csv", _holding("specimen_id,unit,µ\nA,hd42,1\n".encode("latin-1")),
     "cannot read the measurement file: not a text CSV file (not UTF-8; save it as UTF-8 text)"),
    ("folder.csv", lambda p: p.mkdir() or p, "cannot read the measurement file: Is a directory"),
    ("missing.csv", lambda p: p, "cannot read the measurement file: No such file or directory"),
    ("m.xlsx", _holding(b"x"), "unknown file type '.xlsx': measurement files are .csv or .parquet"),
]


@pytest.mark.parametrize("name, make, says", UNREADABLE, ids=[u[0] for u in UNREADABLE])
def test_an_unreadable_file_is_one_problem_naming_it(tmp_path, name, make, says):
    path = make(tmp_path / name)
    lines = _refused(path)
    assert len(lines) == 1 and lines[0].startswith(f"{path}: {says}"), lines


def test_a_flipped_torque_sign_is_refused_per_specimen(tmp_path):
    """Case 5: S2's torque column has the wrong sign; S1 is fine."""
    df = _curve()
    df.loc[9:, "torque_Nm"] *= -1
    lines = _refused(write_table(df, tmp_path))
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"{tmp_path / 'm.csv'}, row 10, field 'torque_Nm': specimen 'S2': "
                               "twist falls as torque rises (least-squares slope -"), lines
    assert "a sign is flipped" in lines[0]


def test_the_sign_test_is_about_the_relation_not_the_signs(tmp_path):
    """Both columns flipped keep the convention (twist rises with torque): the demo loads; either
    one flipped is refused on every specimen."""
    demo = pd.read_csv(SHIPPED / "demo_hd42.csv")
    both = demo.assign(torque_Nm=-demo["torque_Nm"], twist_arcmin=-demo["twist_arcmin"])
    assert len(load_measurements(write_table(both, tmp_path, "both.csv")).specimens) == 16
    lines = _refused(write_table(demo.assign(twist_arcmin=-demo["twist_arcmin"]), tmp_path, "twist.csv"))
    assert len(lines) == 16 and all("field 'torque_Nm'" in s and "a sign is flipped" in s for s in lines)


def test_a_curve_lost_in_its_noise_is_not_called_flipped(tmp_path):
    """A specimen whose play is below the noise may tilt either way by chance: not refused."""
    df = _curve(("S1",))
    df["twist_arcmin"] = 0.001 * np.sign(df["torque_Nm"]) + np.random.default_rng(1).normal(0, 0.02, len(df))
    df["twist_arcmin"] -= 0.004 * df["torque_Nm"]  # a slight downward tilt, well inside the noise
    assert len(load_measurements(write_table(df, tmp_path)).specimens) == 1


def test_a_campaign_for_one_drive_refuses_other_drives_and_bad_ids(tmp_path):
    df = _curve()
    df.loc[9:, "specimen_id"] = "S 2"
    path = write_table(df, tmp_path)
    lines = _refused(path, unit="hd120")
    assert f"{path}, row 1, field 'unit', value 'hd42': specimen 'S1' is not of hd120" in lines[0]
    assert any(s.startswith(f"{path}, row 10, field 'specimen_id', value 'S 2': specimen ids may use") for s in lines)
    assert len(lines) == 3, lines


def test_ids_that_differ_only_in_case_are_refused(tmp_path):
    """'S1' and 's1' are two specimens to pandas but one file name on macOS and Windows, where one
    specimen's table would overwrite the other's: the second is refused, naming the first's row."""
    df = _curve()
    df.loc[9:, "specimen_id"] = "s1"
    path = write_table(df, tmp_path)
    lines = _refused(path, unit="hd42")
    assert lines == [f"{path}, row 10, field 'specimen_id', value 's1': differs from specimen 'S1' (row 1) only in "
                     "case; a campaign names files after ids, and macOS and Windows file systems do not tell them apart"]
    df.loc[:8, "specimen_id"], df.loc[9:, "specimen_id"] = "Straße", "STRASSE"   # not ids at all, not a case clash
    lines = _refused(write_table(df, tmp_path), unit="hd42")
    assert not any("only in case" in line for line in lines) and any("specimen ids may use" in line for line in lines)


def test_a_curve_logged_at_other_steps_or_run_minus_T_first_needs_no_renumbering():
    """Points are compared with the model at their measured torque: the demo curves (5 steps per
    ramp) against a campaign model of 4 or 8 steps per ramp, or run −T first, have no problem."""
    demo = load_measurements(SHIPPED / "demo_hd42.csv")
    assert schedule_problems(demo, 5) == schedule_problems(demo, 4) == schedule_problems(demo, 8) == []
    data = demo.data.copy()
    data["torque_Nm"], data["twist_arcmin"] = -data["torque_Nm"], -data["twist_arcmin"]
    assert schedule_problems(replace(demo, data=data), 5) == []


def test_a_torque_beyond_the_model_test_stops_before_any_solve(tmp_path):
    """The model's curve ends at the test torque (0.96 N·m for HD 42): a reading past it by more
    than a quarter of a load step would be compared with an extrapolation."""
    df = _curve()
    df.loc[2, "torque_Nm"] = 0.96 * (1 + 0.3 / 5)       # 0.3 of a load step beyond
    df.loc[11, "torque_Nm"] = 0.96 * (1 + 0.2 / 5)      # within a quarter: the test torque
    problems = schedule_problems(load_measurements(write_table(df, tmp_path)), 5)
    assert [p[:3] for p in problems] == [(3, "torque_Nm", pytest.approx(1.0176))]
    assert "beyond the campaign model's test torque ±0.96 N·m" in problems[0][3]


def test_parquet_nulls_and_non_numeric_columns_are_refused_not_dropped_or_read_as_numbers(tmp_path):
    """A Parquet null specimen id or drive is an empty one (not the text 'None', and the row is
    not lost); a boolean twist column would read as 0 and 1 arcmin and a datetime torque as
    nanoseconds: both are refused by column type, naming it."""
    df = _curve().astype({"specimen_id": object, "unit": object})
    df.loc[3, "specimen_id"] = None
    df.loc[12, "unit"] = None
    with pytest.raises(MeasurementError) as exc:
        load_measurements(write_table(df, tmp_path, "m.parquet"))
    msg = str(exc.value)
    assert "m.parquet, row 4, field 'specimen_id', value '': empty specimen id" in msg
    assert "m.parquet, row 13, field 'unit'" in msg and "unknown drive" in msg
    typed = _curve().assign(twist_arcmin=lambda d: d["twist_arcmin"] > 0,
                            torque_Nm=pd.Timestamp("2026-01-01") + pd.to_timedelta(np.arange(18), "s"))
    with pytest.raises(MeasurementError) as exc:
        load_measurements(write_table(typed, tmp_path, "t.parquet"))
    msg = str(exc.value)
    assert "field 'twist_arcmin', value 'bool': a column of bool, not numbers" in msg
    assert "field 'torque_Nm', value 'datetime64" in msg and "not numbers" in msg


def test_an_empty_parameter_cell_is_one_problem_and_a_changed_one_names_the_plain_value(tmp_path):
    """An empty cell is reported once (not also as the specimen 'changing' that parameter, as
    it was even for a one-row specimen), and a real change quotes the first row's value as a
    number, not as np.float64(...)."""
    df = _curve()
    df["Gr_mm"] = df["Gr_mm"].astype(object)
    df.loc[6, "Gr_mm"] = ""          # row 7 of S1: empty
    df.loc[7, "Gr_mm"] = 0.013       # row 8 of S1: another value
    with pytest.raises(MeasurementError) as exc:
        load_measurements(write_table(df, tmp_path))
    lines = [l for l in str(exc.value).splitlines() if "Gr_mm" in l]
    assert len(lines) == 2, lines
    assert "row 7, field 'Gr_mm'" in lines[0] and "not a finite number" in lines[0]
    assert "row 8, field 'Gr_mm', value 0.013: specimen 'S1' changes Gr_mm between rows (row 1 has 0.012)" in lines[1]


@pytest.mark.parametrize("name", ["m.csv", "m.parquet"])
def test_a_column_named_twice_is_refused_not_read_as_its_first(tmp_path, name):
    """pandas reads a CSV's repeated column as 'twist_arcmin' and 'twist_arcmin.1' and the loader
    used the first: a second reading (or a pasted block) was silently dropped. Both file types
    name the column and the count."""
    df = _curve()
    df.insert(len(df.columns), "twist_dup", df["twist_arcmin"] + 1.0)
    path = tmp_path / name
    if name.endswith(".csv"):
        df.to_csv(path, index=False, header=[*df.columns[:-1], "twist_arcmin"])
    else:
        import pyarrow as pa
        import pyarrow.parquet as pq
        pq.write_table(pa.Table.from_arrays([pa.array(df[c]) for c in df.columns],
                                            names=[*df.columns[:-1], "twist_arcmin"]), path)
    assert _refused(path) == [f"{path}, field 'twist_arcmin': the header names this column 2 times: keep one"]


@pytest.mark.parametrize("rename, says", [
    ({"u_twist_arcmin": "u_twist_arcmn"}, "field 'u_twist_arcmn': not a column the loader reads: 'u_twist_arcmin' misspelled?"),
    ({"u_twist_arcmin": "U_Twist_Arcmin"}, "field 'U_Twist_Arcmin': not a column the loader reads: 'u_twist_arcmin' misspelled?"),
    ({"u_twist_arcmin": "u_arcmin"}, "field 'u_arcmin': the curve form's uncertainty column is 'u_twist_arcmin'"),
    ({"torque_Nm": "Torque_Nm"}, "field 'Torque_Nm': not a column the loader reads: 'torque_Nm' misspelled?"),
])
def test_a_column_meant_for_the_loader_but_ignored_is_refused(tmp_path, rename, says):
    """Other columns are ignored, so a mistyped uncertainty column made the campaign fall back to
    the stated noise without a word. A name one typo or a case away from an absent read column
    (difflib ratio >= 0.85), or another form's uncertainty column, is refused with the right name."""
    lines = _refused(write_table(_curve().rename(columns=rename), tmp_path))
    assert any(says in line for line in lines), lines


def test_columns_that_merely_resemble_a_present_one_are_still_ignored(tmp_path):
    """A raw twist kept beside the read one, and notes, are the user's own columns: kept, ignored."""
    df = _curve().assign(twist_arcmin_raw=1.0, notes="bench 2")
    assert len(load_measurements(write_table(df, tmp_path)).specimens) == 2


def test_a_file_with_no_measured_quantity_names_no_single_column(tmp_path):
    """A curve file without its torque has no form: the problem is the file's, not that of the
    twist column (which is there), and it lists what was found."""
    lines = _refused(write_table(_curve().drop(columns=["torque_Nm"]), tmp_path))
    assert len(lines) == 1 and lines[0].startswith(f"{tmp_path / 'm.csv'}: no measured quantity: need step, torque_Nm")
    assert "found specimen_id, unit" in lines[0]
