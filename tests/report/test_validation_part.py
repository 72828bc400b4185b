"""Part III of the report, the model against measurements: each campaign's introduction, round
verdicts, ladder sentences and values as they read in the PDF."""

from hdwf.report.document import Document

from test_report_build import PROVENANCE


def test_ladder_is_held_against_the_bearing_rating():
    """The ladder section says which rung's balls exceed ISO 76's 4200 MPa and what that means;
    a rung within it, and a ladder from before the check, say so or nothing."""
    import pandas as pd
    from hdwf.report.validation_part import _bearing_sentence
    lad = pd.DataFrame({"rung": [0, 1], "model": ["baseline", "with preload"],
                        "ball_pressure_max_MPa": [950.0, 5000.0], "specimens_above_iso76": [0, 7],
                        "specimens_checked": [27, 27]})
    said = _bearing_sentence(lad)
    assert "baseline 950 MPa" in said and "with preload 5000 MPa (*7 of 27 specimens above*)" in said
    assert "from rung 1 on" in said and "dent" in said
    assert "Every rung stays within it" in _bearing_sentence(lad.iloc[:1])
    assert _bearing_sentence(lad.drop(columns=["specimens_checked"])) == ""
    # a preload over the rating without the layer, beside the studies' larger one on their layer
    studies = {"preload": {"interference_m": 0.3}, "flank_layer": {"thickness_m": 3900.0}}
    lad["effects"] = ["{}", '{"preload": {"interference_m": 0.186}}']
    assert _bearing_sentence(lad, studies).endswith(
        "The FE studies of Part II carry a larger allowance (0.3 modules) within the rating because their flank layer "
        "takes up the overlap; this campaign's section has no layer, so its bearing holds the overlap.")
    assert "flank layer" not in _bearing_sentence(lad, {"preload": {"interference_m": 0.3}})


def test_ladder_gives_the_solvers_own_contact_check():
    """The largest penetration re-found from scratch at ±T over the rungs, with the rung it is on and
    the limit beyond which a solve fails; "every rung" only when every solved specimen of every rung
    was checked, else the rungs it was not made for are named; a ladder from before the check says
    nothing."""
    import pandas as pd
    from hdwf.report.validation_part import _contact_check_sentence
    lad = pd.DataFrame({"rung": [0, 1, 2], "model": ["baseline", "with preload", "with preload, coning"],
                        "max_penetration_redetected_um": [0.012, 0.0481, float("nan")],
                        "specimens_contact_unchecked": [0, 0, 0]})
    said = _contact_check_sentence(lad)
    assert "at most 0.0481 µm" in said and "over every rung's solves (at rung 1;" in said and "more than 0.5 µm is marked failed" in said
    said = _contact_check_sentence(lad.assign(specimens_contact_unchecked=[27, 0, 3]))
    assert "over the solves that made the check (at rung 1;" in said and "every rung" not in said
    assert "*Not made* for rung 0 (baseline) on 27 specimens; rung 2 (with preload, coning) on 3 specimens" in said
    none = lad.assign(max_penetration_redetected_um=float("nan"), specimens_contact_unchecked=[27, 27, 27])
    assert _contact_check_sentence(none).startswith("The solver's check from scratch at ±T was not made for rung 0")
    assert _contact_check_sentence(lad.assign(max_penetration_redetected_um=float("nan"))) == ""
    assert _contact_check_sentence(lad.drop(columns="max_penetration_redetected_um")) == ""


def test_ladder_names_the_rungs_whose_solve_failed():
    """A rung with a failed specimen has no error in the table (``ladder_table``); the text says which
    rung and specimen, and says nothing when every rung solved or the ladder predates the column."""
    import pandas as pd
    from hdwf.report.validation_part import _failed_rungs_sentence
    lad = pd.DataFrame({"rung": [0, 1], "model": ["baseline", "with preload"], "failed_specimens": ["", "paper-03"],
                        "delta_bic_against_rung": [0, 0]})
    said = _failed_rungs_sentence(lad)
    assert "rung 1 (with preload) for paper-03" in said and "rung 0" not in said and "ΔBIC" not in said
    first_failed = lad.assign(failed_specimens=["paper-03", ""], delta_bic_against_rung=[1, 1])
    assert "ΔBIC is taken against rung 1, the first that solved every specimen" in _failed_rungs_sentence(first_failed)
    assert _failed_rungs_sentence(lad.iloc[:1]) == ""
    assert _failed_rungs_sentence(lad.drop(columns=["failed_specimens"])) == ""


def test_the_one_sentence_verdict_gives_the_ladders_re_solved_error_beside_the_table_estimate():
    """The diagnosis's sentence quotes the final RMSE its calibration tables give (0.2537 on paper_hd42);
    the ladder re-solves it (0.1986). The report says both, each for what it is; a campaign that found
    nothing adds no re-solved figure."""
    from hdwf.report.validation_part import signature_section
    sig = {"terms": [], "noise": {"stated_median_arcmin": None, "estimate_arcmin": 0.2166, "flag": False,
                                  "estimate_from": "scatter", "note": ""}, "significant_z": 3.0,
           "text": "preload, then fs_cup_torsion explained it (RMSE 9.119 → 0.2537 arcmin on the calibration tables)"}
    diag = {"signature": sig, "verdict": {"found_in_order": ["preload", "fs_cup_torsion"]}}
    doc = Document("t", "s", PROVENANCE)
    signature_section(doc, diag, 0.198643)
    said = doc.blocks[-1]["text"]
    assert "0.2537 arcmin on the calibration tables" in said
    assert said.endswith("the last rung of the ladder below has RMSE 0.1986 arcmin.")
    doc = Document("t", "s", PROVENANCE)
    signature_section(doc, {**diag, "verdict": {"found_in_order": []}}, 0.198643)
    assert "ladder" not in doc.blocks[-1]["text"]
    doc = Document("t", "s", PROVENANCE)
    signature_section(doc, diag, float("nan"))     # the last rung failed: no "RMSE – arcmin"
    assert "ladder" not in doc.blocks[-1]["text"]


def test_ladder_rungs_give_the_values_they_were_solved_with():
    """A rung's values are read from the ladder's ``effects`` (the final calibration, not the
    rounds' table estimates), each with its effect's unit, to four significant figures and never
    in exponent notation; the baseline has none."""
    from hdwf.report.document import lit
    from hdwf.report.validation_part import _rung_values
    assert _rung_values("{}") == "–"
    said = _rung_values('{"preload": {"interference_m": 0.18595198}, "fs_cup_torsion": {"K_Nm_per_rad": 302833.88}}')
    assert said == f"{lit('K_Nm_per_rad')} = 302800 N·m/rad; {lit('interference_m')} = 0.186 module"


def test_each_shipped_campaign_says_what_its_data_are_before_anything_else():
    """The shipped campaigns are synthetic data and another model's results, not bench data: the
    config says so for each (``about``), the plan carries it to ``diagnosis.json``, and the
    campaign's chapter opens with it; a campaign without it opens with its measurements."""
    import yaml

    from hdwf.report.validation_part import _campaign_intro
    from hdwf.stages.validation import campaign_plan

    from conftest import ROOT

    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    abouts = {name: campaign_plan(name, camp, config["fe"]).about for name, camp in config["validation"].items()}
    assert "synthetic" in abouts["demo"] and "12 K" in abouts["demo"]
    assert all("not bench data" in abouts[n] and "Ansys" in abouts[n] for n in ("paper_hd42", "paper_hd120"))
    diag = {"measurements": "data/x.csv", "n_specimens": 3, "n_points": 3, "form": "lost_motion",
            "noise_arcmin": None, "mesh": {"elements_over_height": 5, "elements_over_thickness": 3},
            "model": {"fixed": {}}, "ranking": [{"effect": "thermal"}], "about": "synthetic, not bench data"}
    doc = Document("t", "s", {})
    _campaign_intro(doc, diag)
    assert doc.blocks[-1]["text"].startswith("The data: synthetic, not bench data. Measurements: data/x.csv")
    _campaign_intro(doc, {**diag, "about": ""})
    assert doc.blocks[-1]["text"].startswith("Measurements: data/x.csv")


def test_a_round_verdict_names_a_paying_runner_up_and_the_evidence_between_them():
    """The ΔBIC a verdict quotes is against the round's model; when another candidate pays too,
    the verdict gives the gap between the two (Kass–Raftery's scale: 6–10 strong, above 10 very
    strong), and says nothing when no other candidate pays."""
    from hdwf.report.validation_part import _round_verdict

    def cand(effect, dbic, pays=True):
        return {"effect": effect, "params": {"K_Nm_per_rad": 2e4}, "rmse_arcmin": 0.25, "delta_bic": dbic,
                "signature_match": 0.78, "signature": "a slope", "pays": pays}

    rnd = {"round": 2, "current_rmse_arcmin": 0.41,
           "verdict": {"missing_effect": "fs_cup_torsion", "indistinguishable_from": []},
           "ranking": [cand("fs_cup_torsion", -22.2), cand("cs_housing", -14.1), cand("thermal", -3.0, False)]}
    said = _round_verdict(rnd)
    assert "The runner-up, Circular spline and housing compliance," in said and "(ΔBIC -14.1)" in said and "is 8.1 lower, strong evidence" in said
    rnd["ranking"][1]["delta_bic"] = -10.2
    assert "is 12.0 lower, very strong evidence" in _round_verdict(rnd)
    rnd["ranking"][1]["pays"] = False
    assert "runner-up" not in _round_verdict(rnd)


def test_an_effect_found_where_it_was_not_visible_is_flagged_with_both_values():
    """A found effect that the detectability marks invisible at its realistic value was found
    larger than realistic: the report gives the found and the realistic value; a visible or an
    unfound one is not named."""
    from hdwf.report.validation_part import _found_beyond_realistic
    det = {"candidates": [
        {"effect": "fs_cup_torsion", "param": "K_Nm_per_rad", "realistic": 60000.0, "unit": "N·m/rad", "visible": False},
        {"effect": "cs_housing", "param": "k_N_per_mm2", "realistic": 5000.0, "unit": "N/mm²", "visible": False},
        {"effect": "preload", "param": "interference_m", "realistic": 0.15, "unit": "module", "visible": True}]}
    diag = {"final": {"effects": {"preload": {"interference_m": 0.2218},
                                  "fs_cup_torsion": {"K_Nm_per_rad": 20115.6}}}}
    said = _found_beyond_realistic(diag, det)
    assert "= 20120 N·m/rad against a realistic 60000" in said
    assert "housing" not in said and "preload" not in said
    assert _found_beyond_realistic({"final": {"effects": {}}}, det) == ""


def test_the_ladder_table_reads_each_rung_in_words_with_the_effect_it_adds():
    """The rungs are cumulative ('with preload, fs_cup_torsion'): the table names what each adds by
    the effect's own title, the config name beside it, and the campaign model by its effects."""
    from hdwf.report.document import lit
    from hdwf.report.validation_part import rung_in_words
    from hdwf.validation.effects import get as get_effect

    assert rung_in_words("baseline", []) == "our FE model, no effect switched on"
    # the '+' escaped: a typst cell starting '+ ' is a numbered list item ('1. Flexspline …')
    assert rung_in_words("with preload, fs_cup_torsion", []) == f"\\+ Flexspline cup torsion ({lit('fs_cup_torsion')})"
    assert rung_in_words("campaign model", ["preload"]) == (
        f"the campaign's model: {lit(get_effect('preload').title)} ({lit('preload')})")
    assert get_effect("fs_cup_torsion").title == "Flexspline cup torsion"


def test_a_campaign_on_a_coarser_mesh_than_the_studies_says_what_that_costs():
    """The paper campaigns solve on 5 × 3, the studies on 10 × 6: the chapter says so beside the
    mesh, with the scatter it brings (docs/validation.md); a campaign on the studies' mesh, or a
    finer one, says nothing more."""
    from hdwf.drive.design import MeshSettings
    from hdwf.report.validation_part import _campaign_intro

    diag = {"measurements": "data/x.csv", "n_specimens": 3, "n_points": 3, "form": "lost_motion",
            "noise_arcmin": None, "mesh": {"elements_over_height": 5, "elements_over_thickness": 3, "refinement": 1.0},
            "model": {"fixed": {}}, "ranking": [{"effect": "thermal"}]}
    doc = Document("t", "s", {})
    _campaign_intro(doc, diag, MeshSettings())
    assert "5 × 3 elements per tooth (coarser than the studies' 10 × 6" in doc.blocks[-1]["text"]
    assert "ladder's rungs carry that scatter" in doc.blocks[-1]["text"]
    for mesh in ({"elements_over_height": 10, "elements_over_thickness": 6},
                 {"elements_over_height": 5, "elements_over_thickness": 3, "refinement": 2.0}):
        _campaign_intro(doc, {**diag, "mesh": mesh}, MeshSettings())
        assert "coarser" not in doc.blocks[-1]["text"]
    _campaign_intro(doc, diag, MeshSettings(refinement=0.5))      # the studies at 5 × 3 themselves
    assert "coarser" not in doc.blocks[-1]["text"]


def test_a_calibrated_value_is_given_to_the_digits_its_sd_supports_with_its_unit():
    """The sd to two significant figures (0.094, not 9.4e-02) and the value to the same decimal
    place (48600 ± 1800, not 48585.2406 ± 1818.72); no unit on a dimensionless value (μ's '–') nor
    on a missing one (an effect calibrated off); without an sd, four significant figures."""
    from hdwf.report.validation_part import _estimate

    assert _estimate(10.95013, 0.09412, "K") == "10.950 ± 0.094 K"
    assert _estimate(0.3, 0.3201, "–") == "0.30 ± 0.32"
    assert _estimate(None, None, "N/mm²") == "–" and _estimate(float("nan"), 1.0, "K") == "–"
    assert _estimate(48585.2406, 1818.72, "N·m/rad") == "48600 ± 1800 N·m/rad"
    assert _estimate(1000.0, 745.12, "N/mm²") == "1000 ± 750 N/mm²"
    assert _estimate(0.18612, None, "module") == "0.1861 module" and _estimate(2.5, float("inf"), "K") == "2.5 K"


def test_a_one_input_trend_names_the_input_by_its_symbol_and_says_it_is_alone():
    """The signature's trend with d_mm (arcmin per µm) beside the regression test's coefficient of
    d_mm (all five inputs at once) read as two verdicts on d that contradict each other."""
    from hdwf.report.validation_part import _trend_label

    assert _trend_label("d_mm") == "trend with $d$ alone (per µm of it)"
    assert _trend_label("rFS_mm") == 'trend with $r_"FS"$ alone (per µm of it)'
    assert _trend_label("torque_Nm") == "trend with torque\\_Nm"
