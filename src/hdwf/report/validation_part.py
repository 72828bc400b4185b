"""Part III of the report, the model against measurements: a chapter per validation campaign (where
the model fails, which effect is missing round by round, what the data could show at all, the
error ladder), all read from the campaign's ``diagnosis.json``, ladder and figures."""

from __future__ import annotations

import json
import math

import pandas as pd

from hdwf import PARAMETER_COLUMNS, PARAMETERS
from hdwf.common.io import read_json
from hdwf.drive.design import MeshSettings
from hdwf.fe.hertz import ISO76_BALL_PRESSURE_MPA
from hdwf.fe.relinearise import REDETECTED_LIMIT
from hdwf.report.artefacts import CampaignArtefacts
from hdwf.report.document import UNIT_NAMES, Document, fmt, lit, math_label, significant, unit_suffix, with_uncertainty
from hdwf.report.recovery_part import effect_cell, recovery_section
from hdwf.validation.effects import get as get_effect


def _estimate(value: float | None, sd: float | None, unit: str = "") -> str:
    """A calibrated value with its standard deviation when the diagnosis gives one, and its unit
    (none for a dimensionless one or a missing value)."""
    if value is None or not math.isfinite(value):
        return fmt(value)
    return with_uncertainty(value, sd) + unit_suffix(unit)


def _effect_sentence(r: dict) -> str:
    """A found effect in words: its title and calibrated parameter with unit."""
    eff = get_effect(r["effect"])
    (pname, val), = r["params"].items()
    return f"*{lit(eff.title)}* ({lit(pname)} = {_estimate(val, r.get('param_sd'), eff.param(pname).unit)})"


def _rung_values(effects_json: str) -> str:
    """A ladder rung's effects as solved: each calibrated parameter with its unit."""
    effects = json.loads(effects_json)
    parts = [f"{lit(p)} = {significant(v)} {lit(get_effect(e).param(p).unit)}"
             for e, params in sorted(effects.items()) for p, v in params.items()]
    return "; ".join(parts) if parts else "–"


def rung_in_words(model: str, fixed: list[str]) -> str:
    """A ladder rung's label read plainly: what the rung's model is, or what it adds to the rung
    before (``ladder_variants`` labels the found rungs 'with a, b, c', cumulative)."""
    if model == "baseline":
        return "our FE model, no effect switched on"
    if model == "campaign model":
        return "the campaign's model: " + ", ".join(f"{lit(get_effect(e).title)} ({lit(e)})" for e in fixed)
    added = model[len("with "):].split(", ")[-1] if model.startswith("with ") else model
    # escaped: a cell starting '+ ' is a list item in typst
    return f"{lit('+ ' + get_effect(added).title)} ({lit(added)})"


def _detectability_rows(candidates: list[dict]) -> list[list[str]]:
    """Per candidate: its realistic value, the change it makes, the noise it needs, ΔBIC and sd."""
    rows = []
    for c in candidates:
        sd = c["expected_rel_sd"]
        rows.append([effect_cell(c["effect"]), f"{c['realistic']:g}{unit_suffix(c['unit'])}",
                     fmt(c["change_rms_arcmin"], 3), fmt(c["change_max_arcmin"], 3),
                     fmt(c["noise_to_show_arcmin"], 3), fmt(c["noise_to_calibrate_arcmin"], 3),
                     fmt(c["expected_delta_bic"], 1),
                     "–" if sd is None else "> 1000 %" if sd > 10 else f"{fmt(100 * sd, 2)} %",
                     "yes" if c["visible"] else "no"])
    return rows


def _found_beyond_realistic(diag: dict, det: dict) -> str:
    """Found effects the data could not have shown at their realistic value: what was found is
    larger than a realistic one, and the sentence gives both values."""
    final = diag.get("final", {}).get("effects", {})
    parts = []
    for c in det["candidates"]:
        value = final.get(c["effect"], {}).get(c["param"])
        if c["visible"] or value is None:
            continue
        parts.append(f"{lit(c['effect'])} at {lit(c['param'])} = {significant(value)} {lit(c['unit'])} "
                     f"against a realistic {significant(c['realistic'])}")
    if not parts:
        return ""
    return ("Found although this data could not have shown it at a realistic value: " + "; ".join(parts)
            + ". What was found is a larger effect than a realistic one, so it may stand in for more than "
            "that effect.")


def detectability_section(doc: Document, diag: dict, level: int) -> None:
    """Which candidates the campaign's data could have shown at all (``diagnosis.json``: detectability).

    Nothing is added when the diagnosis has no detectability.

    Parameters
    ----------
    doc
        The document to add to.
    diag
        The campaign's ``diagnosis.json``.
    level
        Heading level of the section.
    """
    det = diag.get("detectability")
    if not det:
        return
    doc.heading("What this data could show", level)
    doc.table(["effect", "realistic value", "change RMS", "change max", "noise to show", "noise to calibrate",
               "ΔBIC", "sd of parameter", "visible"], _detectability_rows(det["candidates"]),
              f"Each candidate at a realistic value, against a noise of {fmt(det['noise_arcmin'], 4)} arcmin per "
              f"value ({lit(det['noise_from'])}). Change: what the effect does to the predictions (arcmin). Noise to "
              "show: the largest noise at which it would still pay (ΔBIC ≤ −10); noise to calibrate: at which its "
              "parameter would come out within 15 % (two standard deviations). ΔBIC and sd: what this data would "
              "give if the effect were there at that value (linearised).")
    found_beyond = _found_beyond_realistic(diag, det)
    if found_beyond:
        doc.text(found_beyond)
    hidden = [c for c in det["candidates"] if c["effect"] in diag["verdict"].get("could_not_see", [])]
    if hidden:
        doc.text("This data could not have shown these effects at realistic values, so its verdict says nothing "
                 "about them (not finding them is no evidence that they are absent): " + "; ".join(
            f"{lit(get_effect(c['effect']).title)} (it changes the predictions by {fmt(c['change_rms_arcmin'], 2)} "
            f"arcmin RMS and needs noise below {fmt(c['noise_to_show_arcmin'], 2)} arcmin)" for c in hidden)
            + (". Less noise (averaged repeat runs, a finer encoder), more readings per curve or more specimens "
               "would show them: a parameter's sd falls with the square root of the number of independent readings."
               if diag.get("noise_arcmin") else
               ". No noise is stated, so the final model's residual stands in for it; that residual also holds "
               "whatever error the model cannot explain, and a large model error hides every candidate until it "
               "is explained."))


def refinement_notes(doc: Document, diag: dict) -> None:
    """Which found effects the diagnosis re-solved (before a further round, or for the final model)
    and where; a caution for each re-solve that failed or did not settle.

    Parameters
    ----------
    doc
        The document to add to.
    diag
        The campaign's ``diagnosis.json``.
    """
    logs = [(name, r, False) for name, r in diag.get("refinement", {}).items()]
    logs += [(name, r, True) for name, r in diag.get("final", {}).get("refinement", {}).items()]
    for name, r, final in logs:
        if r.get("solved_at"):
            at = ", ".join(f"{v:.6g}" for v in r["solved_at"])
            why = ("so that the final model (the ladder's last rung) is calibrated on the FE model, not on the "
                   "interpolation of the tabulated values" if final else
                   "so that round weighs its candidates against the FE model, not against the interpolation "
                   "error of the tabulated values")
            when = "For the final model" if final else f"Before round {r['before_round']}"
            doc.text(f"{when}, {lit(name)} was recalibrated on actual FE solves of every specimen at "
                     f"{lit(r['param'])} = {at} (solve {r['solves']}), {why}.")
        if r["status"] in ("failed", "unsettled"):
            doc.text(f"Caution, {lit(name)}: {lit(r['reason'])}.")


def _coarser_mesh(mesh: dict, study_mesh: MeshSettings | None) -> str:
    """What a campaign mesh coarser than the studies' costs, said where its numbers are read."""
    if study_mesh is None:
        return ""
    campaign_scale, study_scale = mesh.get("refinement", 1.0), study_mesh.refinement
    if (mesh["elements_over_height"] * campaign_scale >= study_mesh.elements_over_height * study_scale
            and mesh["elements_over_thickness"] * campaign_scale >= study_mesh.elements_over_thickness * study_scale):
        return ""
    study = f"{study_mesh.elements_over_height * study_scale:g} × {study_mesh.elements_over_thickness * study_scale:g}"
    return (f" (coarser than the studies' {study}, so that every candidate's grid can be "
            "solved: enough to tell effects apart, but a specimen whose flanks sit at the edge of locking can jump "
            "between two nearly equal values of an effect, and the ladder's rungs carry that scatter; "
            "docs/validation.md)")


def _campaign_intro(doc: Document, diag: dict, study_mesh: MeshSettings | None = None) -> None:
    """The measurements, the campaign's model and the candidates tried, in one paragraph."""
    noise = diag.get("noise_arcmin")
    about = f"The data: {lit(diag['about'])}. " if diag.get("about") else ""
    doc.text(f"{about}Measurements: {lit(diag['measurements'])}, {diag['n_specimens']} specimens, {diag['n_points']} values "
             f"({lit(diag['form'])} form)"
             + (f", stated noise {fmt(noise, 4)} arcmin" if noise else ", no noise stated")
             + f". Model: our FE model on a mesh of {diag['mesh']['elements_over_height']} × "
             f"{diag['mesh']['elements_over_thickness']} elements per tooth" + _coarser_mesh(diag["mesh"], study_mesh)
             + (f", with {lit(', '.join(diag['model']['fixed']))} switched on" if diag["model"]["fixed"] else "") + ". "
             + f"Candidates tried: {lit(', '.join(sorted(r['effect'] for r in diag['ranking'])))}.")


def _where_it_fails(doc: Document, diag: dict, campaign: CampaignArtefacts, level: int) -> None:
    """The comparison error overall and per worst specimen, tests on the residuals, and the figures."""
    b = diag["baseline"]
    doc.heading("Where the model fails", level)
    rows = [["RMSE", fmt(b["rmse_arcmin"], 4)], ["bias (mean S − D)", fmt(b["bias_arcmin"], 4)],
            ["largest |E|", fmt(b["max_abs_arcmin"], 4)], ["worst specimen", lit(b["worst_specimen"])]]
    scale = campaign.measured_rms_arcmin()
    if scale is not None:
        rows.insert(0, ["RMS of the measured values D (the scale)", fmt(scale, 4)])
    if b.get("u_val_arcmin") is not None:
        rows += [["u_val (V&V 20)", fmt(b["u_val_arcmin"], 4)],
                 ["points with |E| > 2 u_val", f"{fmt(100 * b['share_beyond_2uval'], 1)} %"]]
    doc.table(["comparison error E = S − D", "arcmin"], rows, "The campaign's model against the measurements.")
    doc.table(["specimen", "RMSE", "bias", "largest |E|"],
              [[lit(w["specimen_id"]), fmt(w["rmse_arcmin"], 4), fmt(w["bias_arcmin"], 4), fmt(w["max_abs_arcmin"], 4)]
               for w in diag["worst_specimens"]], "The specimens where the model fails worst (arcmin).")
    if diag["residual_tests"]:
        doc.table(["test on the residuals", "p-value", "small p means"],
                  [[lit(t["test"]), fmt(t["p_value"], 3), lit(t["meaning"])] for t in diag["residual_tests"]],
                  "statsmodels tests: a small p-value is a pattern in the error that the model does not explain.")
    doc.figure(campaign.measured_png, "Measured against predicted: the campaign's model and the model with the found "
               "effects switched on (calibrated values; table interpolation).")
    along = " and along the test" if diag["form"] == "curve" else ""
    doc.figure(campaign.residuals_png, f"Residuals D − S (measured minus model, the opposite sign of E) against each input (specimen means){along}.")


_TERM_LABELS = {"bias": "level bias", "slope": "slope on torque (compliance)",
                "dead_band": "dead band at zero torque (play width)", "loop_width": "loop width between branches"}


def _trend_label(column: str) -> str:
    """A one-input trend's row: the input by its symbol (``d_mm`` -> $d$), its slope per µm of it."""
    by_column = dict(zip(PARAMETER_COLUMNS, PARAMETERS))
    if column not in by_column:
        return lit(f"trend with {column}")
    return f"trend with {math_label(by_column[column])} alone (per µm of it)"


def _signature_rows(sig: dict) -> list[list[str]]:
    """Per term of the residual's signature: its value (also in arcmin), se and significance; then the noise."""
    rows = []
    for t in sig["terms"]:
        name = t["name"]
        label = lit(_TERM_LABELS[name]) if name in _TERM_LABELS else _trend_label(name.removeprefix("trend_"))
        value = f"{fmt(t['value'], 4)} {t['unit']}"
        if t["unit"] != "arcmin":
            value += f" ({fmt(t['value_arcmin'], 4)} arcmin)"
        if t.get("r_squared") is not None:
            value += f", R² {t['r_squared']:.2f}"
        rows.append([label, lit(value), lit(f"{fmt(t['se'], 4)} {t['unit']}"),
                     "yes" if t["significant"] else "no"])
    n = sig["noise"]
    stated = n.get("stated_median_arcmin")
    rows.append(["noise: stated (median u)", "none" if stated is None else f"{fmt(stated, 4)} arcmin", "–", "–"])
    rows.append(["noise: from the data", "–" if n.get("estimate_arcmin") is None else
                 f"{fmt(n['estimate_arcmin'], 4)} arcmin", "–", "flagged" if n["flag"] else "–"])
    return rows


def signature_section(doc: Document, diag: dict, solved_final_rmse_arcmin: float | None = None) -> None:
    """What the campaign model's residual looks like (``diagnosis.json``: signature): a table of its
    terms and the verdict in one sentence. Nothing is added when the diagnosis has no signature.

    Parameters
    ----------
    doc
        The document to add to.
    diag
        The campaign's ``diagnosis.json``.
    solved_final_rmse_arcmin
        The ladder's last rung (actual solves), said beside the sentence's table estimate.
    """
    sig = diag.get("signature")
    if not sig:
        return
    doc.table(["residual signature", "value", "uncertainty (1 se)", "significant?"], _signature_rows(sig),
              f"Residual signature: the campaign model's residual D − S (measured minus model: the opposite sign "
              f"of the comparison error E = S − D above) split into terms; "
              f"significant beyond {fmt(sig['significant_z'], 1)} standard errors. Trends: the per-specimen mean "
              "residual against each input (in arcmin across the specimens' range). Noise from the data: "
              f"{lit(sig['noise']['estimate_from'])}.")
    if sig["noise"]["flag"]:
        doc.text(f"Caution: {lit(sig['noise']['note'])}.")
    if sig.get("text"):
        solved = ("" if solved_final_rmse_arcmin is None or not math.isfinite(solved_final_rmse_arcmin)
                  or not diag.get("verdict", {}).get("found_in_order") else
                  f" Re-solved with the FE model, the last rung of the ladder below has RMSE "
                  f"{fmt(solved_final_rmse_arcmin, 4)} arcmin.")
        doc.text(f"In one sentence: {lit(sig['text'])}.{solved}")


def _round_table(doc: Document, rnd: dict) -> None:
    """Every candidate of one round, calibrated on top of that round's model."""
    cur = "the campaign's model" if not rnd["model_effects"] else "the model with " + ", ".join(
        lit(get_effect(e).title) for e in rnd["model_effects"])
    rows = []
    for r in rnd["ranking"]:
        (pname, val), = r["params"].items()
        unit = get_effect(r["effect"]).param(pname).unit
        rows.append([effect_cell(r["effect"]), _estimate(val, r.get("param_sd"), unit)
                     + (" (bound)" if r.get("at_bound") else "") + (" (off)" if r.get("calibrated_off") else ""),
                     fmt(r["rmse_arcmin"], 4), fmt(r["delta_bic"], 1), fmt(r["loo_rmse_arcmin"], 4),
                     fmt(r["signature_match"], 2), "yes" if r["pays"] else "no",
                     {True: "yes", False: "no"}.get(r.get("takes_out"), "–")])
    doc.table(["effect", "calibrated", "RMSE", "ΔBIC", "LOO RMSE", "match", "pays", "takes out"], rows,
              f"Round {rnd['round']}: every candidate calibrated on top of {cur} (RMSE "
              f"{fmt(rnd['current_rmse_arcmin'], 4)} arcmin). Pays: ΔBIC ≤ −10 and a lower leave-one-specimen-out "
              "error; match: cosine between the change the effect makes and the residual (1 = same pattern); "
              "takes out: it leaves at most half of the residual's clearest component (the signature's dominant "
              "term along the curve). Only a candidate that pays and takes it out is named.")


def _round_verdict(rnd: dict) -> str:
    """One round's verdict in words: no missing effect, or the effect found and what it does."""
    v = rnd["verdict"]
    if v["missing_effect"] is None:
        paying = [r["effect"] for r in rnd["ranking"] if r["pays"]]
        if paying:
            return (f"Round {rnd['round']}: *no missing effect found.* {lit(', '.join(paying))} lower the error "
                    "beyond the data's scatter, but none takes out the residual's clearest component: each absorbs "
                    "a share of a residual it cannot reproduce (the signature below says what is left).")
        return (f"Round {rnd['round']}: *no missing effect found.* No candidate lowers the error by more than "
                "the data's scatter can explain (ΔBIC above −10, or no gain when a specimen is left out).")
    best = next(r for r in rnd["ranking"] if r["effect"] == v["missing_effect"])
    ties = v["indistinguishable_from"]
    txt = (f"Round {rnd['round']}: the model misses {_effect_sentence(best)}. Switched on, it lowers the error "
           f"from {fmt(rnd['current_rmse_arcmin'], 4)} to {fmt(best['rmse_arcmin'], 4)} arcmin (ΔBIC "
           f"{fmt(best['delta_bic'], 1)}: very strong evidence), also for specimens left out of the fit, "
           f"and the change it makes lines up with the residual (match {fmt(best['signature_match'], 2)}). "
           f"Its signature: {lit(best['signature'])}.")
    if ties:
        txt += (f" The data cannot tell it from {lit(', '.join(ties))}: their signatures coincide here, so the "
                "choice between them needs another test (different torque levels, temperatures or parts).")
    txt += _runner_up(rnd, best, ties)
    if best.get("at_bound"):
        txt += " Its best value sits on the bound of its range: treat it as a stand-in, not an explanation."
    return txt


def _runner_up(rnd: dict, best: dict, ties: list) -> str:
    """The next candidate that pays too, and how far its ΔBIC is from the found effect's: the
    evidence for the choice between them, which the ΔBIC against the round's model does not say."""
    others = [r for r in rnd["ranking"] if r["pays"] and r["effect"] != best["effect"] and r["effect"] not in ties]
    if not others:
        return ""
    nxt = min(others, key=lambda r: r["delta_bic"])
    gap = nxt["delta_bic"] - best["delta_bic"]
    strength = "very strong" if gap > 10 else "strong" if gap > 6 else "positive"
    return (f" The runner-up, {lit(get_effect(nxt['effect']).title)}, pays too (ΔBIC {fmt(nxt['delta_bic'], 1)}); the found effect's "
            f"ΔBIC is {fmt(gap, 1)} lower, {strength} evidence for it over the runner-up (BIC differences of 6–10 "
            "are strong, above 10 very strong).")


def _failed_rungs_sentence(ladder: pd.DataFrame) -> str:
    """The rungs whose solve failed for some specimen, and so have no error (``ladder_table``)."""
    if "failed_specimens" not in ladder:
        return ""
    failed = [f"rung {r['rung']} ({lit(r['model'])}) for {lit(r['failed_specimens'])}"
              for r in ladder.to_dict("records") if r["failed_specimens"]]
    if not failed:
        return ""
    against = int(ladder["delta_bic_against_rung"].iloc[0]) if "delta_bic_against_rung" in ladder else 0
    basis = ("" if against == 0 else " No rung solved every specimen, so no ΔBIC is given." if against < 0 else
             f" ΔBIC is taken against rung {against}, the first that solved every specimen.")
    return f"*No error is given where a rung's solve failed:* {'; '.join(failed)} (see their tables' status).{basis}"


def _contact_check_sentence(ladder: pd.DataFrame) -> str:
    """The solver's own check on the rungs' solves (tooth pairs re-found from scratch at ±T), and
    the rungs with solves it was not made for."""
    if "max_penetration_redetected_um" not in ladder:
        return ""
    unchecked = (ladder[ladder["specimens_contact_unchecked"] > 0] if "specimens_contact_unchecked" in ladder
                 else ladder.iloc[:0])
    missing = ("; ".join(f"rung {int(r['rung'])} ({lit(r['model'])}) on {int(r['specimens_contact_unchecked'])} "
                         f"specimen{'s' if r['specimens_contact_unchecked'] > 1 else ''}"
                         for r in unchecked.to_dict("records")))
    why = "tables solved before the check was recorded, or a coned cup, whose slices keep their settled gaps"
    if ladder["max_penetration_redetected_um"].isna().all():
        return f"The solver's check from scratch at ±T was not made for {missing} ({why})." if missing else ""
    worst = ladder.loc[ladder["max_penetration_redetected_um"].idxmax()]
    return (f"The solver's own check: the tooth pairs, re-found from scratch at ±T, sink at most "
            f"{fmt(worst['max_penetration_redetected_um'], 4)} µm into each other over "
            + ("every rung's solves" if not missing else "the solves that made the check")
            + f" (at rung {int(worst['rung'])}; a solve that leaves more than {REDETECTED_LIMIT * 1000:g} µm "
            "is marked failed)."
            + (f" *Not made* for {missing} ({why})." if missing else ""))


def _layer_note(over: pd.DataFrame, studies_effects: dict | None) -> str:
    """Why the FE studies' larger preload stays within the rating where this campaign's does not."""
    effects = studies_effects or {}
    if "effects" not in over or "flank_layer" not in effects or "preload" not in effects:
        return ""
    first = json.loads(over["effects"].iloc[0])
    if "preload" not in first or "flank_layer" in first:
        return ""
    theirs = effects["preload"]["interference_m"]
    size = "a larger allowance" if theirs > first["preload"]["interference_m"] else "an allowance"
    return (f" The FE studies of Part II carry {size} ({theirs:g} modules) "
            "within the rating because their flank layer takes up the overlap; this campaign's section has no "
            "layer, so its bearing holds the overlap.")


def _bearing_sentence(ladder: pd.DataFrame, studies_effects: dict | None = None) -> str:
    """The rungs held against the wave-generator bearing's static rating (ISO 76, 4200 MPa)."""
    if "specimens_checked" not in ladder or not ladder["specimens_checked"].gt(0).any():
        return ""
    parts = [f"{lit(r['model'])} {fmt(r['ball_pressure_max_MPa'], 0)} MPa"
             + (f" (*{r['specimens_above_iso76']} of {r['specimens_checked']} specimens above*)"
                if r["specimens_above_iso76"] else "")
             for r in ladder.to_dict("records") if r["specimens_checked"] > 0]
    over = ladder[ladder["specimens_above_iso76"] > 0]
    verdict = (f" A model whose balls exceed the rating is not one a real drive of these dimensions could be "
               f"assembled to (its raceways would dent): from rung {int(over['rung'].iloc[0])} on, the found "
               "effect stands in for something the model lacks rather than being it." + _layer_note(over, studies_effects)
               if len(over) else " Every rung stays within it.")
    return ("Is the model physically admissible? The most loaded wave-generator ball at the mount, against the "
            f"{ISO76_BALL_PRESSURE_MPA:g} MPa static rating of ISO 76, rung by rung: " + "; ".join(parts) + "." + verdict)


def campaign_chapter(doc: Document, campaign: CampaignArtefacts, level: int = 2,
                     study_mesh: MeshSettings | None = None, studies_effects: dict | None = None) -> None:
    """One campaign: where the model fails, which effect is missing, what the data could show, the ladder.

    Parameters
    ----------
    doc
        The document to add to.
    campaign
        The campaign's artefacts.
    level
        Heading level of the chapter; its sections are one level below.
    study_mesh
        The FE studies' mesh: a coarser campaign mesh is said to be so, with what that costs.
    studies_effects
        The FE studies' ``fe.effects``: a preload over the bearing's rating is set beside theirs.
    """
    diag = read_json(campaign.diagnosis)
    ladder = pd.read_parquet(campaign.ladder)
    noise = diag.get("noise_arcmin")
    doc.heading(f"Campaign '{campaign.name}' ({UNIT_NAMES[diag['unit']]})", level)
    _campaign_intro(doc, diag, study_mesh)
    _where_it_fails(doc, diag, campaign, level + 1)
    signature_section(doc, diag, float(ladder["rmse_arcmin"].iloc[-1]))
    doc.heading("Which effect is missing", level + 1)
    doc.text("How to read the rounds: each round calibrates every candidate on the specimens' tabulated solves "
             "(interpolated between the candidate's grid values); its value ± 1 standard uncertainty comes from "
             "that fit. An effect a round finds is then re-solved near its estimate on every specimen before the "
             "next round, and the final model is calibrated on such solves too (the notes after the rounds), so "
             "its values and RMSE can differ from a round's table by more than that uncertainty: the table's "
             "interpolation error is not in it. The ladder below holds the re-solved values.")
    for rnd in diag["rounds"]:
        _round_table(doc, rnd)
        doc.text(_round_verdict(rnd))
    refinement_notes(doc, diag)
    detectability_section(doc, diag, level + 1)
    doc.heading("Adding it: the error ladder", level + 1)
    doc.table(["rung", "model", "values solved with", "RMSE", "bias", "largest |E|", "ΔBIC"],
              [[str(r["rung"]), rung_in_words(r["model"], list(diag["model"]["fixed"])), _rung_values(r["effects"]), fmt(r["rmse_arcmin"], 4),
                fmt(r["bias_arcmin"], 4), fmt(r["max_abs_arcmin"], 4), fmt(r["delta_bic"], 1)]
               for r in ladder.to_dict("records")],
              "Each rung re-solved with the FE model (not interpolated), each adding the effect it names to the rung "
              "before: the found effects switched on at their "
              "final calibrated values (after any recalibration on actual solves, so they and the RMSE can differ "
              "from the rounds' table estimates above). ΔBIC against the first rung."
              + (f" Stated noise: {fmt(noise, 4)} arcmin." if noise else ""))
    failed = _failed_rungs_sentence(ladder)
    if failed:
        doc.text(failed)
    contact = _contact_check_sentence(ladder)
    if contact:
        doc.text(contact)
    bearing = _bearing_sentence(ladder, studies_effects)
    if bearing:
        doc.text(bearing)
    doc.figure(campaign.ladder_png, "The error falling rung by rung (each rung adds the effect it names; "
               "a logarithmic axis when the error falls more than tenfold).", width="75%")
    recovery_section(doc, diag, level + 1)
    for name, note in diag.get("notes", {}).items():
        doc.text(f"Note on {lit(name)}: {lit(note)}.")


def validation_part(doc: Document, campaigns: tuple[CampaignArtefacts, ...],
                    study_mesh: MeshSettings | None = None, studies_effects: dict | None = None) -> None:
    """Part III: a chapter per campaign, in config order.

    Parameters
    ----------
    doc
        The document to add to.
    campaigns
        The campaigns shown.
    study_mesh
        The FE studies' mesh (``campaign_chapter``).
    """
    doc.pagebreak()
    doc.heading("Part III — the model against measurements", 1)
    doc.text("Each campaign holds the FE model against a measurement file, shows where it fails, calibrates "
             "every candidate physical effect (each a change to the FE model), names the missing one only "
             "when it pays beyond the noise, and re-solves the model with it switched on "
             "(docs/validation.md).")
    for c in campaigns:
        campaign_chapter(doc, c, 2, study_mesh, studies_effects)
