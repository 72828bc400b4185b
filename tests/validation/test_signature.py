"""The residual's signature (hdwf.validation.signature): each term recovers what was put into a
hand-made residual, the noise is estimated from the data, and the diagnosis and the report
carry it. No FE solves: comparison points are built as the diagnosis builds them."""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hdwf.report.document import Document
from hdwf.report.validation_part import signature_section
from hdwf.validation.comparison import branches, comparison_points
from hdwf.validation.diagnosis import Search, diagnose
from hdwf.common.jsonsafe import json_safe
from hdwf.validation.measurements import Measurements
from hdwf.validation.signature import SIGNIFICANT_Z, residual_signature
from hdwf.validation.variants import plan_variants, variant_key

from conftest import masing_loop

T_TEST = 0.96          # N·m, 4 % of T_N of the HD 42


def _torques(steps_per_ramp: int) -> np.ndarray:
    """The test 0 -> +T -> 0 -> -T -> 0 in ``steps_per_ramp`` steps per ramp."""
    up = np.linspace(0.0, T_TEST, steps_per_ramp + 1)
    return np.concatenate([up, up[-2::-1], -up[1:], -up[-2::-1]])


def _sides(torque: np.ndarray) -> np.ndarray:
    """The sign of the last non-zero torque (0 before any load)."""
    out, s = [], 0.0
    for t in torque:
        s = np.sign(t) if t != 0 else s
        out.append(s)
    return np.array(out)


def _params(s: int) -> dict:
    """Inputs of specimen s: r_FS rises with s, the others cycle with other periods (nearly uncorrelated)."""
    return {"d_mm": 31.0 + 0.004 * (s % 3), "D_mm": 42.0 - 0.004 * (s % 4), "Gr_mm": 0.01 + 0.002 * (s % 5),
            "rFS_mm": 0.002 * s, "rCS_mm": 0.01 + 0.003 * (s % 2)}


def _curves(residual, noise=0.01, u=0.01, n_spec=12, steps_per_ramp=5, seed=1) -> pd.DataFrame:
    """Measured and model curves of ``n_spec`` specimens whose measured - model residual is
    ``residual(T, side, branch, params)`` plus white noise; the diagnosis's comparison points."""
    rng = np.random.default_rng(seed)
    T = _torques(steps_per_ramp)
    side, br = _sides(T), branches(T)
    meas, pred = [], []
    for s in range(n_spec):
        p = _params(s)
        for k in range(len(T)):
            S = 0.3 * side[k] + 0.1 * T[k]
            D = S + residual(T[k], side[k], br[k], p) + noise * rng.normal()
            row = {"specimen_id": f"S{s}", "step": k, **p, "torque_Nm": T[k], "twist_arcmin": D}
            meas.append({**row, "u_twist_arcmin": u} if u is not None else row)
            pred.append({"specimen_id": f"S{s}", "step": k, "twist_arcmin": S})
    return comparison_points(pd.DataFrame(meas), pd.DataFrame(pred), "twist_arcmin")


def test_a_level_offset_is_the_bias():
    """r = 0.3 + noise 0.01: the mean residual is 0.3 with se 0.01/sqrt(n) (n = 252 points), far
    beyond any other term, which are all zero here."""
    sig = residual_signature(_curves(lambda T, side, b, p: 0.3), "curve")
    bias = sig.term("bias")
    n = sig.n_points
    assert n == 12 * 21
    assert bias.se == pytest.approx(0.01 / np.sqrt(n), rel=0.15)
    assert bias.value == pytest.approx(0.3, abs=3 * 0.01 / np.sqrt(n))
    assert sig.dominant == "bias"
    assert f"level offset of {bias.value:.5f} ± {bias.se:.2g} arcmin" in sig.text and "the model fails" in sig.text


def test_a_residual_proportional_to_torque_is_the_slope():
    """r = 0.2 T: the slope of r on torque is 0.2 arcmin/(N·m), 0.192 arcmin at the test torque;
    the mean over the symmetric test is zero, so the slope, not the bias, dominates."""
    sig = residual_signature(_curves(lambda T, side, b, p: 0.2 * T), "curve")
    slope = sig.term("slope")
    assert slope.value == pytest.approx(0.2, abs=3 * slope.se)
    assert slope.value == pytest.approx(0.2, rel=0.03)
    assert slope.value_arcmin == pytest.approx(slope.value * T_TEST)
    assert sig.test_torque_Nm == pytest.approx(T_TEST)
    assert sig.dominant == "slope"
    assert not sig.term("bias").significant


def test_a_hysteresis_loop_is_the_loop_width():
    """A friction-like loop of width w = 0.2: r = -w/2 on the loading branches and +w/2 on the
    unloading ones, in the direction of the torque (on the negative side the unloading branch
    lies below: its twist is more negative), held at zero torque after unloading. The loop width
    comes back within 5 % at every torque level; the zero-torque gap widens by w (a dead band
    error of w, as friction makes it); the slope, fitted with side and branch as regressors,
    stays at zero; the noise estimate is untouched (the loop is constant along a branch)."""
    w = 0.2

    def loop(T, side, branch, p):
        return side * (w / 2 if branch.startswith("unload") else -w / 2)

    sig = residual_signature(_curves(loop), "curve")
    assert sig.term("loop_width").value == pytest.approx(w, rel=0.05)
    assert len(sig.loop_levels) == 4            # |T| = 0.192 ... 0.768 N·m (0 and the peak have no pair)
    assert all(lv.width_arcmin == pytest.approx(w, rel=0.05) and lv.significant for lv in sig.loop_levels)
    assert sig.term("dead_band").value == pytest.approx(w, rel=0.05)
    assert abs(sig.term("slope").value) < SIGNIFICANT_Z * sig.term("slope").se
    assert sig.noise.estimate_arcmin == pytest.approx(0.01, rel=0.25)
    assert sig.dominant == "loop_width" and "hysteresis loop of width 0.20" in sig.text


def test_white_noise_is_estimated_from_second_differences():
    """White noise sigma = 0.05 on 12 curves of 41 points (384 second differences along the
    branches): sqrt(mean(d2^2) / 6) is within 15 % of it; with the bench's 0.05 stated, nothing
    is flagged and no term is significant (seed 3: the largest term is 1.8 se; over seeds 0-11 the
    estimate was 0.90-1.07 sigma)."""
    sig = residual_signature(_curves(lambda T, side, b, p: 0.0, noise=0.05, u=0.05, steps_per_ramp=10,
                                     seed=3), "curve")
    assert sig.noise.n_used == 12 * 4 * 8
    assert sig.noise.estimate_arcmin == pytest.approx(0.05, rel=0.15)
    assert sig.noise.flag is False and sig.noise.note == ""
    assert sig.dominant is None and "no component of the residual stands out" in sig.text
    assert sig.rmse_over_noise == pytest.approx(1.0, rel=0.15)


def test_a_zero_stated_uncertainty_beside_real_noise_is_flagged():
    """u = 0 stated, noise 0.05 in the data: flagged, and the note says the verdict does not use
    it but the detectability does; the signature is read against the estimate."""
    sig = residual_signature(_curves(lambda T, side, b, p: 0.0, noise=0.05, u=0.0, steps_per_ramp=10), "curve")
    assert sig.noise.flag is True
    assert sig.noise.stated_median_arcmin == 0.0
    assert "stated uncertainty 0.000 arcmin is far below the scatter 0.0" in sig.noise.note
    assert "detectability" in sig.noise.note
    assert sig.noise.reference_arcmin == sig.noise.estimate_arcmin
    none_stated = residual_signature(_curves(lambda T, side, b, p: 0.0, noise=0.05, u=None), "curve")
    assert none_stated.noise.flag is True and "no uncertainty is stated" in none_stated.noise.note


def test_a_residual_linear_in_r_fs_is_its_trend():
    """r = 20 arcmin/mm * r_FS = 0.02 arcmin/µm: the per-specimen mean residual follows r_FS with
    that slope and R² near 1 (0.44 arcmin over its 22 µm range); the other inputs cycle
    independently of it and explain little."""
    sig = residual_signature(_curves(lambda T, side, b, p: 20.0 * p["rFS_mm"]), "curve")
    trend = sig.term("trend_rFS_mm")
    assert trend.unit == "arcmin/µm"
    assert trend.value == pytest.approx(0.02, rel=0.02)
    assert trend.r_squared > 0.99
    assert trend.value_arcmin == pytest.approx(0.02 * 22, rel=0.02)
    assert sig.dominant == "trend_rFS_mm"
    assert all(sig.term(f"trend_{c}").r_squared < 0.5 for c in ("d_mm", "D_mm", "Gr_mm", "rCS_mm"))


def test_lost_motion_data_has_bias_trends_and_scatter_only():
    """Φ per specimen (lost_motion form): no torque, so no slope, dead band or loop (left out, said
    why); the bias is the dead-band/level term, and the noise is the scatter after the
    regression on the inputs (0.02 given, 30 specimens)."""
    rng = np.random.default_rng(3)
    rows = [{"specimen_id": f"S{s}", **_params(s), "value": 1.0 + 0.1 + 0.02 * rng.normal(), "step": s,
             "u_arcmin": 0.02} for s in range(30)]
    pred = [{"specimen_id": f"S{s}", "step": s, "value": 1.0} for s in range(30)]
    sig = residual_signature(comparison_points(pd.DataFrame(rows), pd.DataFrame(pred), "value"), "lost_motion")
    assert sig.term("bias").value == pytest.approx(0.1, abs=0.02)
    assert "dead-band/level" in sig.term("bias").unit_note
    assert set(sig.left_out) == {"slope", "dead_band", "loop_width"}
    assert sig.noise.estimate_arcmin == pytest.approx(0.02, rel=0.35)
    assert sig.noise.flag is False


def _measurements_and_tables(delta_T: float, w: float, n_spec=6, steps_per_ramp=5, u_stated=0.005):
    """A hand-made campaign: measurements (curve form) and tables of the model and of the thermal
    candidate, whose change is -0.002 dT * side (the dead band shrinks). The measurements hold
    thermal at ``delta_T`` and a loop of width ``w`` no candidate has."""
    rng = np.random.default_rng(5)
    T = _torques(steps_per_ramp)
    side, br = _sides(T), branches(T)
    u = np.array([1.0 if b.startswith("unload") else -1.0 for b in br])
    data, table = [], []
    for s in range(n_spec):
        base = (0.3 + 0.01 * s) * side + 0.1 * T
        D = base - 0.002 * delta_T * side + w / 2 * side * u + 0.005 * rng.normal(size=len(T))
        data.append(pd.DataFrame({"specimen_id": f"S{s}", "unit": "hd42", **_params(s), "step": np.arange(len(T)),
                                  "torque_Nm": T, "twist_arcmin": D, "u_twist_arcmin": u_stated}))
        for v in plan_variants({}, ["thermal"]):
            dT = v.get("thermal", {}).get("delta_T_K", 0.0)
            table.append(pd.DataFrame({"specimen_id": f"S{s}", "variant": variant_key(v), "step": np.arange(len(T)),
                                       "torque_Nm": T, "twist_arcmin": base - 0.002 * dT * side, "status": "ok"}))
    data = pd.concat(data, ignore_index=True)
    spec = data.groupby("specimen_id", sort=False)[["unit", *_params(0)]].first().reset_index()
    return Measurements(Path("hand.csv"), "curve", data, spec), pd.concat(table, ignore_index=True)


def test_the_diagnosis_carries_the_signature():
    """diagnose() on a hand-made campaign: with only a loop no candidate has, nothing pays and the
    signature (in diagnosis.json, strict JSON) names the loop and the closest candidate; with
    thermal hidden at 10 K as well, thermal is found and the text says it explained it."""
    meas, tables = _measurements_and_tables(delta_T=0.0, w=0.1)
    diag = diagnose(meas, tables, Search(candidates=["thermal"], max_rounds=1)).to_dict()
    assert diag["verdict"]["missing_effect"] is None
    sig = json.loads(json.dumps(json_safe(diag), allow_nan=False))["signature"]
    assert sig["dominant"] == "loop_width"
    loop = next(t for t in sig["terms"] if t["name"] == "loop_width")
    assert loop["value"] == pytest.approx(0.1, rel=0.05) and loop["significant"] is True
    assert "no candidate reproduces it (the closest, thermal" in sig["text"]
    assert sig["n_points"] == diag["n_points"] and sig["noise"]["stated_median_arcmin"] == 0.005
    meas, tables = _measurements_and_tables(delta_T=10.0, w=0.0)
    found = diagnose(meas, tables, Search(candidates=["thermal"], max_rounds=1)).to_dict()
    assert found["verdict"]["missing_effect"] == "thermal"
    assert found["signature"]["dominant"] == "dead_band"        # thermal narrows the play
    assert "thermal explained it" in found["signature"]["text"]


def test_an_understated_uncertainty_is_replaced_by_the_data_scatter_in_the_detectability():
    """Noise 0.005 arcmin in the data: stated as 0.005, the detectability is judged by it; stated
    ten times smaller, the signature flags it and the detectability is judged by the scatter
    estimated from the data instead (second differences, 6 × 21 points: within 25 %)."""
    honest = diagnose(*_measurements_and_tables(0.0, 0.0), Search(candidates=["thermal"], max_rounds=1)).to_dict()
    assert honest["detectability"]["noise_arcmin"] == pytest.approx(0.005)
    assert honest["detectability"]["noise_from"] == "the noise stated in the measurement file"
    low = diagnose(*_measurements_and_tables(0.0, 0.0, u_stated=0.0005),
                   Search(candidates=["thermal"], max_rounds=1)).to_dict()
    assert low["signature"]["noise"]["flag"] is True
    assert low["detectability"]["noise_arcmin"] == pytest.approx(0.005, rel=0.25)
    assert low["detectability"]["noise_arcmin"] == low["signature"]["noise"]["estimate_arcmin"]
    assert low["detectability"]["noise_from"].startswith("the scatter estimated from the data")
    assert low["noise_arcmin"] == pytest.approx(0.0005)     # what the file states stays on record


def test_report_shows_the_signature():
    """The report's table has one row per term plus two noise rows and a significance column; a
    flagged noise adds a caution; a diagnosis.json without a signature (older runs) adds nothing."""
    sig = residual_signature(_curves(lambda T, side, b, p: 0.3, u=0.0), "curve")
    diag = {"signature": json_safe(sig.to_dict())}
    doc = Document("t", "s", {})
    signature_section(doc, diag)
    table = next(b for b in doc.blocks if b["type"] == "table")
    assert len(table["rows"]) == len(sig.terms) + 2
    assert table["rows"][0][0] == "level bias" and table["rows"][0][-1] == "yes"
    texts = [b["text"] for b in doc.blocks if b["type"] != "table"]
    assert texts[0].startswith("Caution") and "far below" in texts[0]
    assert "level offset" in texts[-1]
    empty = Document("t", "s", {})
    signature_section(empty, {})
    assert empty.blocks == []



def test_a_masing_loop_is_named_a_hysteresis_loop_not_play():
    """A loop 0.2 arcmin wide at zero torque: the zero-torque gap is its width, and because the
    branches stay apart under load (a dead band would close) the text calls it a hysteresis loop."""
    T = _torques(5)
    loop = dict(zip(zip(np.round(T, 9), branches(T)), masing_loop(T, 0.2)))
    sig = residual_signature(_curves(lambda t, side, b, p: loop[(round(t, 9), b)], noise=0.008, u=0.008), "curve")
    assert sig.term("dead_band").value == pytest.approx(0.2, rel=0.05)
    assert sig.term("loop_width").significant and sig.term("loop_width").value > 0
    assert "a hysteresis loop 0.20" in sig.text and "play would close under load" in sig.text
