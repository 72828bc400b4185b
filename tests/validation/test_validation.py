"""Comparison statistics and the verdict logic of hdwf.validation.comparison; detectability,
calibration on re-solves (hdwf.validation.calibration) and the report's words on both."""

import numpy as np
import pandas as pd
import pytest

from hdwf.report.document import Document
from hdwf.report.validation_part import detectability_section, refinement_notes
from hdwf.validation.calibration import (CalibrationData, Resolver, Response, anchor_points, anchored_responses,
                                         calibrate, refine_fit, responses)
from hdwf.validation.comparison import Candidate, bic, branches, comparison_points, residual_tests, summarise, verdict
from hdwf.validation.detectability import detectability
from hdwf.validation.diagnosis import Search, _GreedySearch
from hdwf.validation.effects import get
from hdwf.common.jsonsafe import json_safe
from hdwf.validation.variants import plan_variants, variant_key

TORQUES = [0.0, 0.48, 0.96, 0.48, 0.0, -0.48, -0.96, -0.48, 0.0]


def test_branches_of_the_test_sequence():
    assert branches(TORQUES) == ["load+", "load+", "load+", "unload+", "unload+", "load-", "load-", "unload-",
                                 "unload-"]


def _points(bias=0.0, slope_in_rfs=0.0, noise=0.0, n_spec=12, seed=0):
    rng = np.random.default_rng(seed)
    meas, pred = [], []
    for s in range(n_spec):
        rfs = 0.002 * s
        for k, t in enumerate(TORQUES):
            S = 0.3 * np.sign(t) + 0.1 * t
            D = S - bias - slope_in_rfs * rfs + noise * rng.normal()
            common = {"specimen_id": f"S{s}", "step": k, "d_mm": 31.0 + 0.001 * (s % 3), "D_mm": 42.0 - 0.001 * (s % 4),
                      "Gr_mm": 0.01 + 0.001 * (s % 5), "rFS_mm": rfs, "rCS_mm": 0.01 + 0.001 * (s % 2)}
            meas.append({**common, "torque_Nm": t, "twist_arcmin": D, "u_twist_arcmin": max(noise, 1e-3)})
            pred.append({"specimen_id": f"S{s}", "step": k, "twist_arcmin": S})
    return comparison_points(pd.DataFrame(meas), pd.DataFrame(pred), "twist_arcmin")


def test_comparison_error_and_summary():
    pts = _points(bias=0.05)
    assert np.allclose(pts["E"], 0.05)  # E = S - D
    s, per = summarise(pts)
    assert s.rmse == pytest.approx(0.05) and s.bias == pytest.approx(0.05) and s.max_abs == pytest.approx(0.05)
    assert len(per) == 12


def test_validation_uncertainty_by_vv20():
    pts = _points(noise=0.02)
    s, _ = summarise(pts, u_num=0.01, u_input=0.0)
    assert s.u_val == pytest.approx(np.sqrt(0.01 ** 2 + 0.02 ** 2))
    # Gaussian noise only: about 5 % of the points beyond 2 u_D, far fewer than a model error gives
    assert s.share_beyond_2uval < 0.15


def test_residual_tests_find_a_trend_in_an_input_and_not_in_noise():
    trend = residual_tests(_points(slope_in_rfs=20.0, noise=0.01)).set_index("test")
    assert trend.loc["error ~ inputs: rFS_mm", "p_value"] < 1e-3
    clean = residual_tests(_points(noise=0.01, seed=3)).set_index("test")
    assert clean.loc["error ~ inputs (OLS F-test)", "p_value"] > 0.01


def test_bic_prefers_the_true_model():
    # BIC = n ln(RSS/n) + k ln n: one extra parameter must buy a factor exp(ln n / n) of RSS.
    assert bic(1.0, 100, 2) - bic(1.0, 100, 1) == pytest.approx(np.log(100))
    assert bic(0.5, 100, 2) < bic(1.0, 100, 1)


def test_verdict_names_the_effect_ties_and_none():
    base = Candidate("baseline", {}, rss=1.0, n=200, k=0, loo_rmse=0.071)
    strong = Candidate("tooth_friction", {"mu": 0.08}, rss=0.2, n=200, k=1, loo_rmse=0.032)
    twin = Candidate("cs_housing", {"k": 1e5}, rss=0.205, n=200, k=1, loo_rmse=0.033)
    weak = Candidate("thermal", {"dT": 1.0}, rss=0.99, n=200, k=1, loo_rmse=0.070)
    v = verdict(base, [weak, twin, strong])
    assert v.missing_effect == "tooth_friction"
    assert v.indistinguishable_from == ["cs_housing"]
    assert [r.effect for r in v.ranking] == ["tooth_friction", "cs_housing", "thermal"]
    none = verdict(base, [weak])
    assert none.missing_effect is None and "no missing effect" in none.text
    # a candidate that pays but leaves the residual's clearest component is not named
    v = verdict(base, [weak, twin, strong], takes_out={"tooth_friction": False, "cs_housing": True, "thermal": True})
    assert v.missing_effect == "cs_housing" and v.indistinguishable_from == []
    assert v.ranking[0].pays and v.ranking[0].takes_out is False
    v = verdict(base, [twin, strong], takes_out={"tooth_friction": False, "cs_housing": False})
    assert v.missing_effect is None and v.text == "no missing effect found"


def _linear_response(g):
    """Flank friction's response made exactly linear in mu: the change at mu is mu * g."""
    t = np.array([0.0, 0.1, 0.2, 0.3])
    return Response("tooth_friction", "mu", t, t[:, None] * g[None, :], (0.0, 0.3))


def test_detectability_of_a_linear_effect():
    """Change at the realistic mu = 0.08 is 0.08 g; the parameter's relative sd is sigma/|change|
    (linear least squares); at the stated 'noise to show' the effect earns exactly the pay
    threshold, ΔBIC = -10, by the BIC of hdwf.validation.comparison."""
    rng = np.random.default_rng(3)
    g = rng.normal(0.0, 1.0, 200)
    resp = {"tooth_friction": _linear_response(g)}
    size = 0.08 * np.linalg.norm(g)
    row, = detectability(resp, noise=0.05, n=200)
    assert row.change_rms_arcmin == pytest.approx(size / np.sqrt(200), rel=1e-9)
    assert row.expected_rel_sd == pytest.approx(0.05 / size, rel=1e-9)
    s = row.noise_to_show_arcmin
    # data holding the effect (RSS n s^2 + |change|^2) against the fitted model (RSS n s^2), one more parameter
    d_bic = bic(200 * s**2, 200, 1) - bic(200 * s**2 + size**2, 200, 0)
    assert d_bic == pytest.approx(-10.0, abs=1e-9)
    assert row.visible == (0.05 < s)
    assert row.noise_to_calibrate_arcmin == pytest.approx(0.075 * size)
    # twice the noise at which it just shows: no longer visible
    assert detectability(resp, noise=2 * s, n=200)[0].visible is False


def test_report_says_which_effects_the_data_could_not_show():
    """The report's table and sentence come from diagnosis.json: a candidate the data could not
    show is named with the noise it needs; a perfect fit (noise 0: sd null in the JSON) prints
    a dash, not an error; a found effect is not listed as unseen."""
    g = np.linspace(-1.0, 1.0, 100)
    resp = {"tooth_friction": _linear_response(g)}
    rows = json_safe([r.as_dict() for r in detectability(resp, noise=1.0, n=100)])
    diag = {"noise_arcmin": 1.0, "verdict": {"could_not_see": ["tooth_friction"]},
            "detectability": {"noise_arcmin": 1.0, "noise_from": "stated", "candidates": rows}}
    doc = Document("t", "s", {})
    detectability_section(doc, diag, 2)
    table = next(b for b in doc.blocks if b["type"] == "table")
    assert table["rows"][0][-1] == "no"
    sentence = doc.blocks[-1]["text"]
    assert "Coulomb friction on the tooth flanks" in sentence
    assert f"needs noise below {rows[0]['noise_to_show_arcmin']:.2f}" in sentence
    rows0 = json_safe([r.as_dict() for r in detectability(resp, noise=0.0, n=100)])
    assert rows0[0]["expected_delta_bic"] is None and rows0[0]["visible"] is True
    diag0 = {"noise_arcmin": 0.0, "verdict": {"could_not_see": []},
             "detectability": {"noise_arcmin": 0.0, "noise_from": "stated", "candidates": rows0}}
    doc0 = Document("t", "s", {})
    detectability_section(doc0, diag0, 2)
    assert doc0.blocks[-1]["type"] == "table" and doc0.blocks[-1]["rows"][0][-1] == "yes"


def _kinked_thermal(n_points=60, seed=5):
    """A thermal response with kinks between the table's grid values (teeth closing one by
    one): twist_i(dT) = base_i - g_i max(dT - k_i, 0), g_i > 0 (the dead band shrinks), kinks
    k_i in 11..14 or 20..23 K (straight in between); and a ``solve`` that returns it exactly for
    any variant, counting its calls."""
    rng = np.random.default_rng(seed)
    g = rng.uniform(0.01, 0.03, n_points)
    k = np.where(np.arange(n_points) % 2 == 0, rng.uniform(11, 14, n_points), rng.uniform(20, 23, n_points))
    base = rng.normal(1.0, 0.3, n_points)
    steps = np.arange(n_points)
    calls = []

    def twist(variant):
        dT = variant.get("thermal", {}).get("delta_T_K", 0.0)
        return base - g * np.maximum(dT - k, 0.0)

    def solve(variants):
        calls.append(len(variants))
        return pd.concat([pd.DataFrame({"specimen_id": "s1", "variant": variant_key(v), "step": steps,
                                        "torque_Nm": np.sin(steps), "twist_arcmin": twist(v), "status": "ok"})
                          for v in variants], ignore_index=True)

    table = solve(plan_variants({}, ["thermal"]))
    calls.clear()
    obs = pd.DataFrame({"specimen_id": "s1", "step": steps, "torque_Nm": np.sin(steps), "quantity": "twist"})
    return table, obs, twist, solve, calls


def test_anchoring_on_actual_solves_removes_the_tables_interpolation_error():
    """Between the thermal grid's values (every 10 K) kinks make the table's spline wrong: a
    calibration on it misses dT = 17 K of noise-free data by 0.19 K. Anchored on exact solves
    around its estimate (three, in one call), the response is exact there (straight between
    the kinks, so the quadratic through the three is exact) and the calibration recovers
    17 K; the log says where it solved."""
    table, obs, twist, solve, calls = _kinked_thermal()
    resp = responses(table, obs, {}, ["thermal"])
    data = CalibrationData(twist({"thermal": {"delta_T_K": 17.0}}), twist({}), resp)
    plain = calibrate(data, ["thermal"])
    assert abs(plain.t[0] - 17.0) > 0.1           # the spline's error shows in the estimate (0.19 K)
    log = {}
    fit = refine_fit(data, plain, Resolver(solve, obs, {}, dict(resp)), log, before_round=2)
    assert fit.t[0] == pytest.approx(17.0, abs=1e-6)
    assert fit.rss == pytest.approx(0.0, abs=1e-16)
    assert calls == [3]
    lo, hi = resp["thermal"].anchor[0][[0, -1]]
    assert lo <= 17.0 <= hi and hi - lo == pytest.approx(2.0)     # ± a tenth of the 10 K spacing
    assert log["thermal"].status == "anchored" and log["thermal"].before_round == 2
    assert log["thermal"].solved_at == pytest.approx([lo, (lo + hi) / 2, hi])


def test_the_effect_found_in_the_last_round_is_anchored_for_the_final_model(caplog):
    """A search of one round finds thermal on the table's spline (0.19 K off the true 17 K
    between the kinks) and has no further round to anchor it before. The final model is
    anchored all the same (one solve of three values), so the estimate the ladder re-solves is
    the true 17 K, and the log says it was for the final model."""
    table, obs, twist, solve, calls = _kinked_thermal()
    resp = responses(table, obs, {}, ["thermal"])
    data = CalibrationData(twist({"thermal": {"delta_T_K": 17.0}}), twist({}), resp)
    specimen = obs["specimen_id"].to_numpy()
    search = _GreedySearch(data, specimen, Search(max_rounds=1), Resolver(solve, obs, {}, dict(resp)))
    with caplog.at_level("INFO", logger="hdwf.validation.diagnosis"):
        search.run(["thermal"])
    assert search.on == ["thermal"] and calls == [3]
    # the job's log tells the search as it went: the round's decision, then the final re-solve
    # with the value it gave (the rule's log held nothing but scikit-fem's assembly lines)
    round_line, final_line = [r.getMessage() for r in caplog.records]
    assert round_line.startswith("round 1 on the campaign's model") and "thermal is missing" in round_line
    assert final_line.startswith("for the final model, thermal: anchored (delta_T_K solved at 15.858, ")
    assert final_line.endswith("now {'delta_T_K': %r}" % float(search.fit.t[0]))
    assert search.fit.t[0] == pytest.approx(17.0, abs=1e-6)
    assert search.refinement == {}                    # no round came after the first
    log = search.final_refinement["thermal"].as_dict()
    assert log["status"] == "anchored" and log["solves"] == 1 and "before_round" not in log


def test_an_effect_unsettled_in_a_fresh_log_is_logged_not_a_crash(monkeypatch):
    """The final pass logs into a log of its own, so an effect can run out of solves there
    without an entry from an earlier solve of that pass (another effect took them all); with
    no solves allowed at all, that is the first check: it must be logged as unsettled, keeping
    the table's response, not raise KeyError."""
    import hdwf.validation.calibration as calibration
    table, obs, twist, solve, calls = _kinked_thermal()
    resp = responses(table, obs, {}, ["thermal"])
    data = CalibrationData(twist({"thermal": {"delta_T_K": 17.0}}), twist({}), resp)
    plain = calibrate(data, ["thermal"])
    monkeypatch.setattr(calibration, "ANCHOR_SOLVES", 0)
    log = {}
    fit = refine_fit(data, plain, Resolver(solve, obs, {}, dict(resp)), log, before_round=None)
    assert calls == [] and fit.t[0] == plain.t[0]
    assert log["thermal"].status == "unsettled" and "after 0 solves" in log["thermal"].reason


def test_an_anchored_response_is_exact_at_the_grid_and_off_at_zero():
    """Outside its solved interval the anchored response is the table's spline shifted to meet
    the solves, the shift fading to zero at the next grid value: it stays continuous at the
    interval's ends and equals the table (an actual solve) at every grid value, so t = 0
    still means "off"."""
    table, obs, twist, solve, _ = _kinked_thermal()
    resp = responses(table, obs, {}, ["thermal"])["thermal"]
    anchored = anchored_responses(Resolver(solve, obs, {}, {"thermal": resp}), {"thermal": 16.3})["thermal"]
    for t in resp.t:                                   # the grid, incl. 0 and the bounds
        np.testing.assert_allclose(anchored.change(t), resp.change(t), atol=1e-12)
    np.testing.assert_allclose(anchored.change(0.0), 0.0, atol=1e-12)
    for edge in anchored.anchor[0][[0, -1]]:             # continuous where the quadratic ends
        np.testing.assert_allclose(anchored.change(edge - 1e-9), anchored.change(edge + 1e-9), atol=1e-9)
        exact = twist({"thermal": {"delta_T_K": edge}}) - twist({})
        np.testing.assert_allclose(anchored.change(edge), exact, atol=1e-12)


def test_a_failed_anchor_solve_keeps_the_table_and_says_so():
    """A solve that raises, or returns a failed status, must not lose the diagnosis: the
    table's response is kept, the estimate is the table's, and the log names the failure (and
    the specimen whose solve failed)."""
    table, obs, twist, solve, _ = _kinked_thermal()
    S0, D = twist({}), twist({"thermal": {"delta_T_K": 17.0}})

    def crashes(variants):
        raise RuntimeError("worker died")

    def fails(variants):
        out = solve(variants)
        out["twist_arcmin"], out["status"] = np.nan, "failed: no convergence"
        return out

    for bad, reason in ((crashes, "RuntimeError: worker died"), (fails, "(s1, ")):
        resp = responses(table, obs, {}, ["thermal"])
        data = CalibrationData(D, S0, resp)
        plain = calibrate(data, ["thermal"])
        log = {}
        fit = refine_fit(data, plain, Resolver(bad, obs, {}, dict(resp)), log, before_round=2)
        assert fit.t[0] == plain.t[0] and resp["thermal"].anchor is None
        assert log["thermal"].status == "failed" and reason in log["thermal"].reason
        assert "the table's response is used" in log["thermal"].reason
        if bad is fails:
            assert "failed: no convergence" in log["thermal"].reason


def test_anchor_points_of_a_stiffness_stay_inside_its_values():
    """Housing stiffness is tabulated in t = k^-3/4, where t = 0 ("off", k infinite) is not
    a value: an estimate at or near 0 is solved at three finite stiffnesses within the
    parameter's bounds, in increasing t, a tenth of the grid spacing apart."""
    p = get("cs_housing").param("k_N_per_mm2")
    lo, hi = p.t_bounds
    resp = Response("cs_housing", p.name, np.array([lo, hi]), np.zeros((2, 1)), (lo, hi))
    h = 0.1 * (hi - lo) / p.grid_points
    for t_hat in (0.0, 1e-9, hi, 0.5 * hi):
        ts, values = anchor_points(resp, t_hat)
        assert np.all(np.diff(ts) > 0) and np.diff(ts) == pytest.approx([h, h])
        assert all(p.lower <= v <= p.upper for v in values)


def test_report_says_where_an_effect_was_re_solved():
    """diagnosis.json's ``refinement`` in words: the values solved at, and a caution when a
    solve failed (the sentence must not claim a recalibration that did not happen)."""
    diag = {"refinement": {
        "thermal": {"status": "anchored", "before_round": 2, "param": "delta_T_K",
                    "solved_at": [10.1468, 11.1468, 12.1468], "solves": 1},
        "cs_housing": {"status": "failed", "reason": "the solve failed (failed: no convergence); "
                                                    "the table's response is used"}}}
    doc = Document("t", "s", {})
    refinement_notes(doc, diag)
    texts = [b["text"] for b in doc.blocks]
    assert len(texts) == 2
    assert "Before round 2" in texts[0] and "10.1468, 11.1468, 12.1468" in texts[0]
    assert texts[1].startswith("Caution") and "no convergence" in texts[1] and "recalibrated" not in texts[1]
    doc = Document("t", "s", {})
    refinement_notes(doc, {"final": {"refinement": {"preload": {"status": "anchored", "param": "interference_m",
                                                                "solved_at": [0.18, 0.185, 0.19], "solves": 1}}}})
    assert doc.blocks[0]["text"].startswith("For the final model, preload was recalibrated")
