"""The error ladder (``hdwf.validation.ladder``) on hand-made tables: its rungs, their errors and
the bearing check that says whether a found effect is one a real drive could have."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hdwf.fe.hertz import ISO76_BALL_PRESSURE_MPA
from hdwf.validation.ladder import bearing_check, contact_check, ladder_table, ladder_variants
from hdwf.validation.measurements import Measurements
from hdwf.validation.variants import TABLE_COLUMNS, variant_key

PRELOAD = {"preload": {"interference_m": 0.2}}


def _rows(sid, effects, lost_motion, pressure, penetration_um=0.01):
    """One variant's test 0 -> +T -> 0 -> -T -> 0 whose lost motion is ``lost_motion``."""
    tw = np.array([0.0, 0.5, 0.1, 0.5 - lost_motion, 0.0])
    return pd.DataFrame({"specimen_id": sid, "variant": variant_key(effects), "step": np.arange(5),
                         "torque_Nm": [0.0, 0.96, 0.0, -0.96, 0.0], "twist_arcmin": tw, "status": "ok",
                         "ball_pressure_max_MPa": pressure,
                         "max_penetration_redetected_um": penetration_um})[TABLE_COLUMNS]


def _campaign():
    meas = pd.DataFrame({"specimen_id": ["s1", "s2"], "lost_motion_arcmin": [1.0, 2.0]})
    m = Measurements(Path("lm.csv"), "lost_motion", meas, meas.assign(unit="hd42"))
    table = pd.concat([_rows("s1", {}, 3.0, 900.0), _rows("s2", {}, 4.0, 950.0),
                       _rows("s1", PRELOAD, 1.1, 3000.0, 0.03), _rows("s2", PRELOAD, 1.9, 5000.0, 0.2)],
                      ignore_index=True)
    return m, table


def test_rungs_switch_the_found_effects_on_in_order():
    rungs = ladder_variants({}, [("preload", {"interference_m": 0.2}), ("fs_cup_torsion", {"K_Nm_per_rad": 2e5})])
    assert [label for label, _ in rungs] == ["baseline", "with preload", "with preload, fs_cup_torsion"]
    assert rungs[2][1] == {"preload": {"interference_m": 0.2}, "fs_cup_torsion": {"K_Nm_per_rad": 2e5}}


def test_ladder_gives_each_rungs_error_and_holds_it_against_the_bearing():
    """Errors 2 and 2 arcmin on the bare rung (RMSE 2), +0.1 and -0.1 with the preload (RMSE 0.1);
    the preloaded balls reach 3000 and 5000 MPa: one of two specimens above ISO 76's 4200 MPa."""
    meas, table = _campaign()
    lad = ladder_table(meas, table, ladder_variants({}, [("preload", {"interference_m": 0.2})]))
    assert lad["rmse_arcmin"].tolist() == pytest.approx([2.0, 0.1])
    assert lad["bias_arcmin"].tolist() == pytest.approx([2.0, 0.0], abs=1e-12)
    assert lad["ball_pressure_max_MPa"].tolist() == [950.0, 5000.0]
    assert lad["specimens_above_iso76"].tolist() == [0, 1]
    assert lad["specimens_checked"].tolist() == [2, 2]
    assert ISO76_BALL_PRESSURE_MPA == 4200


def test_a_table_without_pressures_checks_nothing():
    """Tables written before the column existed: no number is made up."""
    _, table = _campaign()
    got = bearing_check(table.drop(columns="ball_pressure_max_MPa"), variant_key(PRELOAD))
    assert np.isnan(got["ball_pressure_max_MPa"]) and got["specimens_checked"] == 0
    failed = table.assign(ball_pressure_max_MPa=np.where(table["specimen_id"] == "s2", np.nan, 3000.0))
    assert bearing_check(failed, variant_key(PRELOAD))["specimens_checked"] == 1


def test_each_rung_carries_the_solvers_own_contact_check():
    """The largest penetration re-found from scratch at +-T over a rung's specimens: 0.01 um on the
    bare rung, 0.2 um (s2) with the preload, every solved specimen checked. A specimen without the
    value (a table from before the column, a coned cup) is counted as unchecked, not read as 0 or
    as covered by the others; a failed solve is neither."""
    meas, table = _campaign()
    lad = ladder_table(meas, table, ladder_variants({}, [("preload", {"interference_m": 0.2})]))
    assert lad["max_penetration_redetected_um"].tolist() == pytest.approx([0.01, 0.2])
    assert lad["specimens_contact_unchecked"].tolist() == [0, 0]
    key = variant_key(PRELOAD)
    s2 = (table["specimen_id"] == "s2") & (table["variant"] == key)
    unchecked = table.assign(max_penetration_redetected_um=np.where(s2, np.nan, table["max_penetration_redetected_um"]))
    assert contact_check(unchecked, key) == {"max_penetration_redetected_um": pytest.approx(0.03),
                                            "specimens_contact_unchecked": 1}
    failed = unchecked.assign(status=np.where(s2, "failed: no contact pair", unchecked["status"]))
    assert contact_check(failed, key)["specimens_contact_unchecked"] == 0
    old = contact_check(table.drop(columns="max_penetration_redetected_um"), key)
    assert np.isnan(old["max_penetration_redetected_um"]) and old["specimens_contact_unchecked"] == 2


def test_a_rung_whose_solve_failed_for_a_specimen_has_no_error():
    """s2's preloaded solve fails. Scored on s1 alone (error 0.1) over both observations, that rung
    would read RMSE 0.0707 and beat one that solved both; it must have no error at all, and say
    which specimen failed. The bare rung, solved for both, keeps its RMSE of 2."""
    meas, table = _campaign()
    failed = (table["specimen_id"] == "s2") & (table["variant"] == variant_key(PRELOAD))
    table.loc[failed, "twist_arcmin"] = np.nan
    table.loc[failed, "status"] = "failed: no contact pair"
    lad = ladder_table(meas, table, ladder_variants({}, [("preload", {"interference_m": 0.2})]))
    assert lad["rmse_arcmin"].iloc[0] == pytest.approx(2.0)
    assert lad["solved"].tolist() == [True, False]
    assert lad["failed_specimens"].tolist() == ["", "s2"]
    assert lad.loc[1, ["rmse_arcmin", "bias_arcmin", "max_abs_arcmin", "delta_bic"]].isna().all()


def test_a_failed_baseline_leaves_the_later_rungs_comparable():
    """The bare rung fails for s2: it has no BIC, so ΔBIC is taken against the first rung that solved
    every specimen (the preload, ΔBIC 0 there) and the ladder says which rung that is."""
    meas, table = _campaign()
    failed = (table["specimen_id"] == "s2") & (table["variant"] == variant_key({}))
    table.loc[failed, "twist_arcmin"] = np.nan
    lad = ladder_table(meas, table, ladder_variants({}, [("preload", {"interference_m": 0.2})]))
    assert np.isnan(lad.loc[0, "delta_bic"]) and lad.loc[1, "delta_bic"] == 0.0
    assert lad["delta_bic_against_rung"].tolist() == [1, 1]
    assert lad.loc[1, "rmse_arcmin"] == pytest.approx(0.1)
