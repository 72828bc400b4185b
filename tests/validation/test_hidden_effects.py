"""Hidden-effect tests on the paper's design space: 12 HD 42 specimens drawn from Table 3's
ranges, curves of 21 points (5 steps per ramp). The dead-band effects (thermal, Oldham play) are
found at 2 % noise, the elastic ones rightly not claimed there, no hidden effect gives no
verdict, and catalogue-size hysteresis loops are found or described. Set-up, noise levels and
why: hidden_setup.py; the catalogue-grade batch: test_hidden_effects_dense.py."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from hdwf.validation.detectability import detectability_of_tables
from hdwf.validation.diagnosis import Search, diagnose
from hdwf.validation.measurements import load_measurements
from hdwf.validation.synthesis import synth_designs
from hdwf.validation.variants import candidate_names, mean_lost_motion, plan_variants, variant_key

from conftest import masing_loop
from hidden_setup import N_SPECIMENS, REALISTIC, SEED, STEPS, UNIT, campaign_tables, hidden_one, measure

# every test here solves the FE model (the module's tables alone take minutes)
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def specimens():
    return synth_designs(UNIT, N_SPECIMENS, SEED)


@pytest.fixture(scope="module")
def tables(specimens):
    return campaign_tables(specimens, STEPS)


@pytest.fixture(scope="module")
def signal(tables):
    """Mean lost motion of the specimens (the twist range of each baseline curve)."""
    return mean_lost_motion(tables)


@pytest.mark.parametrize("effect", ["thermal", "oldham_play"])
def test_dead_band_effect_found_at_two_percent_noise(tmp_path, specimens, tables, signal, effect):
    hidden_one(tmp_path, specimens, tables, effect, 0.02 * signal)


def test_no_hidden_effect_no_verdict(tmp_path, specimens, tables, signal):
    """The baseline model itself plus noise: nothing may pay."""
    meas = measure(tmp_path, specimens, {}, 0.02 * signal)
    diag = diagnose(meas, tables).to_dict()
    assert diag["verdict"]["missing_effect"] is None, diag["verdict"]
    assert diag["verdict"]["text"] == "no missing effect found"


def test_elastic_effects_are_not_claimed_below_the_noise(tmp_path, specimens, tables, signal):
    """Cup torsion at a realistic stiffness under 2 % noise, on 21-point curves: too few
    readings for a change well below the noise (it is found on the dense catalogue-grade batch above), so
    the honest answer is no verdict, not a guess."""
    param, true = REALISTIC["fs_cup_torsion"]
    meas = measure(tmp_path, specimens, {"fs_cup_torsion": {param: true}}, 0.02 * signal)
    diag = diagnose(meas, tables).to_dict()
    assert diag["verdict"]["missing_effect"] is None, diag["verdict"]
    # ... and it says why: at their realistic values these effects are below this data's noise
    assert {"fs_cup_torsion", "cs_housing", "tooth_friction"} <= set(diag["verdict"]["could_not_see"])
    assert not {"thermal", "oldham_play"} & set(diag["verdict"]["could_not_see"])


def test_effect_switched_on_for_calibration_comes_first(tmp_path, specimens, tables, signal):
    """``effects: {fs_cup_torsion: {K_Nm_per_rad: calibrate}}`` in a campaign: the effect is
    calibrated before the search; the search then finds the hidden temperature difference on
    top of it. (Two dead-band effects, e.g. thermal and Oldham play, would trade off against
    each other: the data fix only their sum, which is why the verdict calls them
    indistinguishable.)"""
    noise = 0.002 * signal
    hidden = {"thermal": {"delta_T_K": 12.0}, "fs_cup_torsion": {"K_Nm_per_rad": 6.0e4}}
    meas = measure(tmp_path, specimens, hidden, noise)
    diag = diagnose(meas, tables, Search(calibrate_first=["fs_cup_torsion"])).to_dict()
    assert [f["effect"] for f in diag["found"]][0] == "fs_cup_torsion"
    assert diag["verdict"]["found_in_order"][0] == "thermal"
    assert diag["final"]["effects"]["fs_cup_torsion"]["K_Nm_per_rad"] == pytest.approx(6.0e4, rel=0.15)
    assert diag["final"]["effects"]["thermal"]["delta_T_K"] == pytest.approx(12.0, rel=0.15)


def test_tables_key_every_variant(tables):
    """Every planned variant solved for every specimen (one status per curve)."""
    plan = [variant_key(v) for v in plan_variants({})]
    assert set(tables["variant"]) == set(plan)
    assert tables.groupby(["specimen_id", "variant"]).size().eq(21).all()


def test_friction_below_what_bench_noise_can_show_is_said(tmp_path, specimens, tables, signal):
    """Flank friction at mu = 0.08 changes these curves by a few thousandths of an arcmin RMS:
    the detectability table must say that 0.2 % noise on 21-point curves of the paper's design
    space cannot show it at that value. (With this seed the search names it all the same,
    mu = 0.0925: 16 % off.)"""
    meas = measure(tmp_path, specimens, {"tooth_friction": {"mu": 0.08}}, 0.002 * signal)
    diag = diagnose(meas, tables).to_dict()
    row = next(c for c in diag["detectability"]["candidates"] if c["effect"] == "tooth_friction")
    assert not row["visible"] and row["noise_to_show_arcmin"] < 0.002 * signal
    assert row["change_rms_arcmin"] < 0.01
    # unseen, or found (then its value is off, 16 %): never both, never neither
    found = "tooth_friction" in diag["verdict"]["found_in_order"]
    assert found != ("tooth_friction" in diag["verdict"]["could_not_see"])


def test_plan_before_measuring_predicts_what_the_diagnosis_reports(tmp_path, specimens, tables, signal):
    """`hdwf plan` (detectability from the tables alone, before any measurement) must give the
    same table as the diagnosis of data measured on those specimens at that noise: both see
    the same points, so the same change vectors."""
    noise = 0.02 * signal
    plan = detectability_of_tables(tables, UNIT, noise, candidate_names({})).to_dict()
    assert plan["n_specimens"] == N_SPECIMENS and plan["n_points"] == 21 * N_SPECIMENS
    assert plan["mean_lost_motion_arcmin"] == pytest.approx(signal)
    meas = measure(tmp_path, specimens, {}, noise)
    diag = diagnose(meas, tables).to_dict()
    got = {c["effect"]: c for c in diag["detectability"]["candidates"]}
    for c in plan["candidates"]:
        d = got[c["effect"]]
        assert c["change_rms_arcmin"] == pytest.approx(d["change_rms_arcmin"], rel=1e-12)
        assert c["noise_to_show_arcmin"] == pytest.approx(d["noise_to_show_arcmin"], rel=1e-12)
        assert c["visible"] == d["visible"]
    # at 2 % noise the plan says: the dead-band effects and a catalogue-size loop (0.2 arcmin at
    # zero torque, Φ up by 0.4) show, the elastic ones do not
    vis = {c["effect"]: c["visible"] for c in plan["candidates"]}
    assert vis == {"thermal": True, "oldham_play": True, "microslip_hysteresis": True, "fs_cup_torsion": False,
                   "cs_housing": False, "tooth_friction": False}



def _measured_with_loop(tmp_path, specimens, tables, loop, noise):
    """Bench data: the campaign model's own curves, a Masing hysteresis loop ``loop`` arcmin wide
    and white noise (seeded)."""
    rng = np.random.default_rng(SEED)
    base = tables[tables["variant"] == variant_key({})]
    rows = []
    for spec in specimens.to_dict(orient="records"):
        g = base[base["specimen_id"] == spec["specimen_id"]].sort_values("step")
        T = g["torque_Nm"].to_numpy()
        twist = g["twist_arcmin"].to_numpy() + masing_loop(T, loop) + rng.normal(0.0, noise, len(T))
        rows += [{**spec, "step": int(k), "torque_Nm": t, "twist_arcmin": w, "u_twist_arcmin": noise}
                 for k, t, w in zip(g["step"], T, twist)]
    path = tmp_path / "loop.csv"
    pd.DataFrame(rows).to_csv(path, index=False)
    return load_measurements(path)


LOOP_NOISE = 0.008   # arcmin per reading (0.5 arcsec)


@pytest.mark.parametrize("loop", [0.05, 0.2, 0.5])
def test_a_catalogue_size_hysteresis_loop_is_found(tmp_path, specimens, tables, loop):
    """A hysteresis loop of catalogue size made by a Masing law written out here, at 0.008 arcmin
    noise: micro-slip hysteresis is named, its loop width recovered within 15 %, and switched on
    the model meets the data to 1.5× the noise. (Its final RMSE comes from the tables: a series
    element acts on the solved curve exactly as a single solve applies it, which
    test_hysteresis_effect.py checks, so no re-solve is needed here.)"""
    meas = _measured_with_loop(tmp_path, specimens, tables, loop, LOOP_NOISE)
    diag = diagnose(meas, tables).to_dict()
    assert diag["verdict"]["missing_effect"] == "microslip_hysteresis", diag["verdict"]
    assert diag["verdict"]["found_in_order"] == ["microslip_hysteresis"]
    est = next(r for r in diag["ranking"] if r["effect"] == "microslip_hysteresis")["params"]["loop_arcmin"]
    assert est == pytest.approx(loop, rel=0.15)
    assert diag["final"]["effects"] == {"microslip_hysteresis": {"loop_arcmin": est}}
    assert diag["final"]["rmse_arcmin"] <= 1.5 * LOOP_NOISE, diag["final"]


def test_a_loop_no_candidate_offers_is_described_by_its_signature(tmp_path, specimens, tables):
    """The same 0.2 arcmin loop with no hysteresis candidate offered: the compliances pay by
    absorbing the loop's mean curve (cup torsion halves the RMSE) but leave the loop itself, so
    none is named: "no missing effect found", and the residual's signature names a hysteresis loop
    of the right width (within 20 %) and the closest candidate."""
    meas = _measured_with_loop(tmp_path, specimens, tables, 0.2, LOOP_NOISE)
    others = [c for c in candidate_names({}) if c not in ("microslip_hysteresis", "tooth_friction")]
    diag = diagnose(meas, tables, Search(candidates=others)).to_dict()
    assert diag["verdict"]["missing_effect"] is None and diag["verdict"]["text"] == "no missing effect found"
    closest = diag["rounds"][0]["ranking"][0]
    assert closest["pays"] and closest["takes_out"] is False
    sig = diag["signature"]
    assert sig["dominant"] == "dead_band"
    gap = next(t for t in sig["terms"] if t["name"] == "dead_band")
    assert gap["value_arcmin"] == pytest.approx(0.2, rel=0.2)
    assert "a hysteresis loop" in sig["text"], sig["text"]
    assert f"no candidate reproduces it (the closest, {closest['effect']}" in sig["text"], sig["text"]
