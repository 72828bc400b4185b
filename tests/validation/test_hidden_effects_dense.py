"""Hidden-effect tests on a catalogue-grade batch: 12 HD 42 specimens with tight bearing fits,
Table 3's smallest radial clearance and tooth offsets within 2 µm of the zero-backlash design
(lost motion about 1.15 arcmin), logged at 201 points per curve. The elastic effects are found
and recovered at 2 % noise, and two hidden effects in two rounds. Set-up, noise levels and why:
hidden_setup.py."""

from __future__ import annotations

import pytest

from hdwf.validation.diagnosis import diagnose
from hdwf.validation.synthesis import synth_designs
from hdwf.validation.variants import mean_lost_motion, specimen_solver

from hidden_setup import (BATCH, BATCH_VALUES, DENSE_STEPS, N_SPECIMENS, SEED, UNIT, campaign_tables, hidden_one,
                          measure, rmse_switched_on, solve_setup)

# every test here solves the FE model (the module's tables alone take minutes)
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def batch_specimens():
    return synth_designs(UNIT, N_SPECIMENS, SEED, BATCH)


@pytest.fixture(scope="module")
def dense_tables(batch_specimens):
    return campaign_tables(batch_specimens, DENSE_STEPS)


@pytest.fixture(scope="module")
def batch_signal(dense_tables):
    """Mean lost motion of the catalogue-grade batch (about 1.15 arcmin on this mesh)."""
    return mean_lost_motion(dense_tables)


@pytest.mark.parametrize("effect", ["fs_cup_torsion", "cs_housing", "tooth_friction"])
def test_elastic_effect_found_at_two_percent_noise_on_a_dense_catalogue_grade_batch(
        tmp_path, batch_specimens, dense_tables, batch_signal, effect):
    """A batch of catalogue-grade drives (lost motion about 1.15 arcmin) logged at 201 points
    per curve: 2 % of its lost motion is 0.023 arcmin (1.4 arcsec) per reading. Cup torsion
    (expected sd of K 1.4 %), housing compliance (4 %) and flank friction at mu 0.1 (10 %) are
    each named first and recovered within 15 %. Housing compliance and friction have no
    look-alike; cup torsion's data fit housing compliance almost as well (ΔBIC -2572.0 against
    -2566.3, within the tie threshold of 6), so housing may be named beside it."""
    diag = hidden_one(tmp_path, batch_specimens, dense_tables, effect, 0.02 * batch_signal, DENSE_STEPS, BATCH,
                       BATCH_VALUES)
    # stricter than the "first or among the indistinguishable": named first, and a
    # look-alike only where the two compliances fit alike
    look_alikes = {"fs_cup_torsion": {"cs_housing"}}.get(effect, set())
    assert diag["verdict"]["missing_effect"] == effect
    assert set(diag["verdict"]["indistinguishable_from"]) <= look_alikes


def test_two_hidden_effects_found_in_two_rounds(tmp_path, batch_specimens, dense_tables, batch_signal):
    """A temperature difference (12 K) and cup torsion, noise of 1.4 % of the signal (the
    information per curve of 2 % at 401 points) on the dense catalogue-grade batch. Round 1
    finds the temperature; before round 2 it is recalibrated on actual solves near its
    estimate, because near zero clearance the teeth close one by one between the 10 K values
    of its grid and the table's spline is off there. On the tables alone round 2 cannot tell
    cup torsion from housing compliance, which absorbs that spline error (their ΔBIC within
    the tie threshold, seed 11); with the re-solves cup torsion wins outright and both values
    come back within 15 %."""
    hidden = {"thermal": {"delta_T_K": 12.0}, "fs_cup_torsion": {"K_Nm_per_rad": 6.0e4}}
    noise = 0.014 * batch_signal
    meas = measure(tmp_path, batch_specimens, hidden, noise, DENSE_STEPS, BATCH)

    # the control: on the tables' splines alone, round 2 is a tie between the two compliances
    tables_only = diagnose(meas, dense_tables).to_dict()
    assert tables_only["verdict"]["found_in_order"][0] == "thermal"
    second = tables_only["rounds"][1]["verdict"]
    assert {second["missing_effect"], *second["indistinguishable_from"]} == {"fs_cup_torsion", "cs_housing"}

    diag = diagnose(meas, dense_tables, solve=specimen_solver(solve_setup(DENSE_STEPS), batch_specimens)).to_dict()
    assert diag["verdict"]["found_in_order"] == ["thermal", "fs_cup_torsion"]
    assert diag["refinement"]["thermal"]["status"] == "anchored"
    assert diag["rounds"][1]["verdict"]["indistinguishable_from"] == []
    cup = next(r for r in diag["rounds"][1]["ranking"] if r["effect"] == "fs_cup_torsion")
    # cup torsion's own joint fit: its stiffness and the temperature calibrated with it
    both = {"fs_cup_torsion": cup["params"], **cup["with_effects"]}
    assert both["fs_cup_torsion"]["K_Nm_per_rad"] == pytest.approx(6.0e4, rel=0.15)
    assert both["thermal"]["delta_T_K"] == pytest.approx(12.0, rel=0.15)
    # both switched on at those values, actual solves: the error is the noise
    assert rmse_switched_on(meas, batch_specimens, both, DENSE_STEPS) <= 1.3 * noise
