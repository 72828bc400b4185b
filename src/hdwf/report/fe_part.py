"""Part II of the report, our FE model: the model and its settings, mesh convergence, torque–twist
curves, agreement with the paper's FEA at its design points (``agreement_part``), the Sobol' indices of every study
beside the paper's, and the statistics of each FE study. Figures that no rule makes (curves,
agreement) are drawn into a scratch folder the caller owns."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from hdwf import PARAMETERS
from hdwf.common.io import read_json
from hdwf.drive.geometry import E_STEEL, unit_data
from hdwf.fe.changes import ModelChanges
from hdwf.fe.cycle import EXIT_ARC_DEG
from hdwf.fe.hertz import ISO76_BALL_PRESSURE_MPA
from hdwf.fe.solver import TOL_GAP
from hdwf.report.agreement_part import AGREEMENT_TARGETS, agreement_section, effects_text, fe_mesh_changes
from hdwf.report.artefacts import FeSettings, ReportInputs, StudyArtefacts
from hdwf.report.catalogue_part import catalogue_section
from hdwf.report.document import UNIT_NAMES, Document, fmt, lit, math_label
from hdwf.report.figures import curves_figure
from hdwf.report.knee_part import knee_section, rank_split_section
from hdwf.report.paper_part import correlation_section, exact_sobol, sobol_section, surrogate_section
from hdwf.report.references import cite
from hdwf.study.paper import load_published


def _assumption_rows(assumptions: list[dict]) -> list[list[str]]:
    """One row per quantity with both drives' values side by side (a value for both in one cell)."""
    by_name: dict[str, dict] = {}
    for a in assumptions:
        row = by_name.setdefault(a["name"], {"source": a["source"]})
        row[a["unit"]] = a["value"]
    return [[f"`{name}`", lit(r.get("HD 42", r.get("both", "–"))), lit(r.get("HD 120", r.get("both", "–"))),
             lit(r["source"])] for name, r in by_name.items()]


def fe_model_section(doc: Document, assumptions: tuple[dict, ...], pictures: dict[str, Path],
                     settings: FeSettings, level: int = 1) -> None:
    """The FE model in words, its settings, every assumed value and the deformed-mesh pictures.

    Parameters
    ----------
    doc
        The document to add to.
    assumptions
        Rows of ``hdwf.drive.geometry.assumptions_table``.
    pictures
        Drive name -> picture of its deformed mesh.
    settings
        The FE settings of the studies.
    level
        Heading level of the section.
    """
    doc.heading("The FE model", level)
    doc.text(f"A 2D plane-stress section of each drive (gmsh mesh {cite('gmsh')}, scikit-fem assembly {cite('skfem')}, linear-elastic steel, "
             "$E = 210$ GPa, $nu = 0.3$, thickness = face width) with unilateral frictionless contact between the "
             "locked wave-generator cam and the bearing inner ring, the balls and both raceways (radial clearance "
             "$G_r$), the outer ring and the flexspline bore (fit from $D$) and the flexspline and circular-spline "
             "tooth flanks. The circular spline is held at its outer rim; the test torque acts on the flexspline. "
             "The contact solver is our own (see `hdwf.fe`).")
    mesh = settings.mesh
    doc.text(f"Settings: {mesh.elements_over_height} elements over the tooth height and "
             f"{mesh.elements_over_thickness} over its thickness (the paper's rule) times a refinement "
             f"of {mesh.refinement:g}"
             + (f", every flank divided into {mesh.flank_refinement:g} times as many segments "
                f"({mesh.segments_per_flank} a flank, `fe.flank_refinement`)"
                if mesh.flank_refinement != 1 else "")
             + (f", the tip corners rounded {settings.tip_round_m:g} m (`fe.tip_round_m`)" if settings.tip_round_m else "")
             + (", the flank layer integrated along the FS outline alone (one contact pass, "
                "`fe.flank_layer_fs_pass_only`)" if settings.flank_layer_fs_pass_only else "")
             + f"; {settings.steps_per_ramp} load steps per ramp; "
             + ("the half model (angles 0 to π tied by the drive's 180° point symmetry, which reproduces the "
                "full model's $Phi$ within 0.05 %, `docs/fe-model.md`)." if mesh.symmetry == "half"
                else "the full model."))
    if settings.effects:
        doc.text(f"Switched on in the FE studies (`fe.effects`): {effects_text(settings.effects)}"
                 + (f", the values set on {UNIT_NAMES[settings.calibrated_on]}’s data only; the other drive is a "
                    "blind prediction with the same values" if settings.calibrated_on else "")
                 + " (`docs/fe-model.md`, \"The studies' model\"). The validation campaigns of Part III start "
                 "from the bare section instead." + _layer_sentence(settings))
    doc.table(["quantity", "HD 42", "HD 120", "source or reason"], _assumption_rows(assumptions),
              "The constants of both drives: those the paper gives, with its table, and those it does not, "
              "with the reason for the value assumed.")
    preloaded = (settings.effects.get("preload") or {}).get("interference_m", 0) > 0
    gaps = ("the flanks touch (preloaded) and the white gaps are the tip/root clearance" if preloaded
            else "the white gaps are the clearance that $r_\"FS\"$ and $r_\"CS\"$ open on the flanks")
    for label, path in pictures.items():
        doc.figure(path, f"{label}: the teeth at the major axis at +4 % $T_N$, true scale; from the left the "
                   "bearing's outer ring (grey), the FS wall and its teeth, the CS teeth and rim. Colour: the von "
                   "Mises stress the test torque adds, where the load goes (the scale ends at the 99th percentile); "
                   f"{gaps}.", width="75%")


def _layer_sentence(settings: FeSettings) -> str:
    """The flank layer's thickness in modules as the compliance it stands for, on each drive."""
    if not settings.effects.get("flank_layer"):
        return ""
    t = settings.effects["flank_layer"]["thickness_m"]
    calibrated = (f", set so that the level matches the paper's on {UNIT_NAMES[settings.calibrated_on]}"
                  if settings.calibrated_on else "")
    per_drive = ", ".join(f"{fmt(ModelChanges(flank_layer_m=t).layer_um_per_MPa(unit_data(u).module, E_STEEL), 3)} "
                          f"µm/MPa on {UNIT_NAMES[u]}" for u in ("hd42", "hd120"))
    return (f" The layer is no physical layer: its {t:g} modules are the compliance per unit flank area of a steel "
            f"layer that thick, c = t m / E ({per_drive}), the give under each tooth that a plane section lacks "
            f"(cup wall, diaphragm, the face across its width){calibrated}.")


def _convergence_rows(conv: pd.DataFrame, levels: tuple[str, ...]) -> list[list[str]]:
    """Per design: Φ on each mesh, the change between the two finest, the GCI and its order."""
    rows = []
    for r in conv.to_dict("records"):
        rows.append([lit(r["design_id"]), *[fmt(r.get(f"phi_{k}_arcmin"), 4) for k in levels],
                     fmt(r.get("rel_change_fine", np.nan) * 100, 2),
                     fmt(r.get("gci_fine", np.nan) * 100, 2) + ("\\*" if r.get("asymptotic") is False else ""),
                     fmt(r.get("order_p"), 2), _verdict(r)])
    return rows


BELOW_RESOLUTION = "*res.*"   # the mark of a miss of 2 % within what the contact tolerance resolves


def _verdict(r: dict) -> str:
    """'yes' within 2 %; otherwise *no*, or *res.* when the change is below what the contact
    tolerance resolves (Φ small: 2 % of it is less than the solver can tell apart)."""
    if r["converged"]:
        return "yes"
    return BELOW_RESOLUTION if r.get("within_resolution") is True else "*no*"


def convergence_section(doc: Document, study: StudyArtefacts, level: int = 1) -> None:
    """Lost motion of the study's designs on three meshes, the change and the GCI per drive.

    Parameters
    ----------
    doc
        The document to add to.
    study
        The mesh-convergence study (its drives have ``convergence``).
    level
        Heading level of the section.
    """
    doc.heading("Mesh convergence", level)
    doc.text("The designs of the `fe` study are solved on other meshes too (element density factors below): every "
             "design on the two finest, representative designs also on the third. The grid convergence index "
             f"(Celik et al. {cite('celik')}) uses the tooth element size as the mesh size; *change* is the relative "
             "difference of $Phi$ between the two finest meshes, required below 2 %. The change is no error "
             "bound: where the three meshes give no order (marked \\*) they are not yet in the asymptotic range, "
             "and the GCI, not the change, estimates the error; docs/fe-model.md (Mesh convergence) holds the "
             "default mesh against meshes up to 3× finer.")
    levels = ("fine", "medium", "coarse")
    for drive in study.drives:
        conv = pd.read_parquet(drive.convergence)
        first = conv.iloc[0]
        heads = [f"$Phi$ at {first.get(f'refinement_{k}', np.nan):g}×" for k in levels]
        n_ok = int(conv["converged"].sum())
        doc.table(["design", *heads, "change (%)", "GCI (%)", "order $p$", "< 2 %"], _convergence_rows(conv, levels),
                  f"{UNIT_NAMES[drive.unit]}: $Phi$ (arcmin) on three meshes (every design on the two finest, "
                  f"representative designs also on the coarsest, which gives the GCI); {n_ok} of {len(conv)} "
                  f"designs converged{_below_resolution(conv)}{_where_it_misses(conv)}; largest change {fmt(conv['rel_change_fine'].max() * 100, 2)} %, median GCI "
                  f"{fmt(conv['gci_fine'].median() * 100 if 'gci_fine' in conv else np.nan, 2)} %. \\* no order of "
                  "convergence in [0.5, 10] fits the three values (pre-asymptotic or oscillating): GCI with safety "
                  "factor 3 and first order.")


def _within_resolution(conv: pd.DataFrame) -> pd.Series:
    """Per design: does Phi change by no more than the contact tolerance resolves (False on tables
    from before the resolution was recorded)."""
    if "within_resolution" not in conv:
        return pd.Series(False, index=conv.index)
    return conv["within_resolution"].eq(True)


def _below_resolution(conv: pd.DataFrame) -> str:
    """The designs that miss 2 % by less than the solver resolves, said as such."""
    if "within_resolution" not in conv:
        return ""
    n = int((~conv["converged"].astype(bool) & _within_resolution(conv)).sum())
    return (f", and {n} more ({BELOW_RESOLUTION}) change by more than 2 % but by less than the solver resolves "
            f"({fmt(conv['resolution_arcmin'].iloc[0], 4)} arcmin: 4 × {TOL_GAP * 1000:g} µm over the base radius; "
            "2 % of their small $Phi$ is below that)") if n else ""


def _where_it_misses(conv: pd.DataFrame) -> str:
    """The median Phi of the designs that miss by more than the resolution against the converged
    ones', and the docs' diagnosis of a locked design's Phi only when theirs is the smaller."""
    converged = conv["converged"].astype(bool)
    miss = conv.loc[~converged & ~_within_resolution(conv), "phi_fine_arcmin"].dropna()
    ok = conv.loc[converged, "phi_fine_arcmin"].dropna()
    if miss.empty or ok.empty:
        return ""
    said = (f"; the {len(miss)} that miss by more have median $Phi$ {fmt(miss.median(), 3)} arcmin (largest "
            f"{fmt(miss.max(), 3)}), the converged ones {fmt(ok.median(), 3)} arcmin")
    if miss.median() < ok.median():
        said += (": the misses are at the smaller $Phi$, and docs/fe-alternatives.md (Mesh-convergence "
                 "experiments) traces a locked design's $Phi$ to preloaded flank contacts carried by one or two "
                 "nodes each")
    return said


def _redetected(lm: pd.DataFrame) -> str:
    """The solver's check from scratch at ±T over a study's designs; nothing where no design has it
    (an older run, or coned cups, whose slices are not re-paired: NaN)."""
    pen = lm.get("max_penetration_redetected_um")
    if pen is None or not pen.notna().any():
        return ""
    solved = lm["status"].eq("ok") if "status" in lm else pd.Series(True, index=lm.index)
    unchecked = int((solved & pen.isna()).sum())
    return (f", re-found from scratch at ±T {fmt(pen.max(), 4)} µm"
            + (f" (not checked on {unchecked} solved design{'s' if unchecked > 1 else ''})" if unchecked else ""))


def _solve_summary(name: str, lm: pd.DataFrame) -> str:
    """How many designs solved, the teeth in contact, the penetration and the solve times."""
    failed = lm[lm["lost_motion_arcmin"].isna()]
    timing = (f"Solve time per design: median {fmt(lm['solve_s'].median(), 1)} s, largest "
              f"{fmt(lm['solve_s'].max(), 1)} s; one factorisation {fmt(lm['factorize_s'].median(), 2)} s; "
              f"ratio solve/factorise median {fmt((lm['solve_s'] / lm['factorize_s']).median(), 1)}.")
    return (f"{name}: {len(lm) - len(failed)} of {len(lm)} designs solved"
            + (f"; failed: {lit(', '.join(failed.design_id))} ({lit(failed.iloc[0].status)})" if len(failed) else "")
            + f". Teeth in contact at the test torque: {int(lm['teeth_in_contact'].min())}–"
              f"{int(lm['teeth_in_contact'].max())}; largest penetration {fmt(lm['max_penetration_um'].max(), 4)} µm"
            + _redetected(lm) + ". "
            + _unsolved_overlap(lm) + _exit_zone_load(lm) + _ball_load(lm) + timing)


def _ball_load(lm: pd.DataFrame) -> str:
    """The most loaded wave-generator ball at the mount against the bearing's static rating."""
    if "ball_pressure_max_MPa" not in lm or lm["ball_pressure_max_MPa"].isna().all():
        return ""
    load, pressure = lm["ball_load_max_N"], lm["ball_pressure_max_MPa"]
    over = pressure > ISO76_BALL_PRESSURE_MPA
    text = (f"The most loaded wave-generator ball carries {fmt(load.min(), 0)}–{fmt(load.max(), 0)} N at the mount "
            f"(median {fmt(load.median(), 0)} N), a raceway pressure of {fmt(pressure.min(), 0)}–"
            f"{fmt(pressure.max(), 0)} MPa")
    if not over.any():
        return text + f", within the {ISO76_BALL_PRESSURE_MPA:g} MPa of the static rating of ISO 76 {cite('iso76')}. "
    return (text + f"; in {int(over.sum())} of {len(lm)} designs above the {ISO76_BALL_PRESSURE_MPA:g} MPa of "
            f"the static rating of ISO 76 {cite('iso76')}, where the raceways dent: a drive preloaded that hard would be damaged at "
            "assembly, so the allowance cannot be read as a real interference of the drive "
            "(docs/fe-model.md, \"Preloaded engagement\"). ")



def _exit_zone_load(lm: pd.DataFrame) -> str:
    """The designs whose torque is carried in part by teeth far out in the exit zone."""
    if "loaded_arc_deg" not in lm:
        return ""
    arc = lm["loaded_arc_deg"]
    far = arc > EXIT_ARC_DEG
    if not far.any():
        return f"Every loaded tooth at +T lies within {fmt(arc.max(), 1)}° of a major axis. "
    return (f"In {int(far.sum())} of {len(lm)} designs teeth farther than {EXIT_ARC_DEG:g}° from a major axis "
            f"carry load at +T (out to {fmt(arc.max(), 1)}°): relieved tips still crossing on the way out of "
            "mesh, from the uniform preload allowance. The paper reports tooth interference in its own model "
            "too, near the minor axis and 60° from it; a deeper cam that engages the major axis only "
            "matches HD 120 but not HD 42 (docs/fe-alternatives.md, \"A deeper cam\"). ")


def _unsolved_overlap(lm: pd.DataFrame) -> str:
    """The teeth outside the solved zones that overlap at the mount: contacts the model does not see."""
    if "overlap_outside_zones_um" not in lm or not (lm["overlap_outside_zones_um"] > 0).any():
        return ""
    over = lm["overlap_outside_zones_um"]
    return (f"Teeth outside the solved zones overlap at the mount in {int((over > 0).sum())} of {len(lm)} "
            f"designs, by up to {fmt(over.max(), 1)} µm (median {fmt(over.median(), 1)} µm): with the assumed "
            "involute tips, FS and CS tips cross where the teeth leave the engagement, where the solver does not "
            "watch them (tip relief, docs/fe-model.md). ")


def curves_section(doc: Document, study: StudyArtefacts, tmp: Path, level: int = 1) -> None:
    """Torque–twist curves of the designs with the smallest, median and largest lost motion.

    Parameters
    ----------
    doc
        The document to add to.
    study
        An FE study (its drives have ``curves``).
    tmp
        A scratch folder for the figures; it must outlive ``doc.compile``.
    level
        Heading level of the section.
    """
    doc.heading("Torque–twist curves", level)
    for drive in study.drives:
        name = UNIT_NAMES[drive.unit]
        lm = pd.read_parquet(drive.lost_motion)
        ok = lm[lm["lost_motion_arcmin"].notna()].sort_values("lost_motion_arcmin")
        if ok.empty:
            continue
        picks = list(dict.fromkeys([ok.iloc[0].design_id, ok.iloc[len(ok) // 2].design_id, ok.iloc[-1].design_id]))
        path = tmp / f"curves_{drive.unit}.png"
        curves_figure(pd.read_parquet(drive.curves), lm, picks, f"{name}: smallest, median and "
                      "largest Φ of the fe study", path)
        doc.figure(path, f"{name}: torque–twist curves of the test 0 → +4 % → 0 → −4 % → 0 $T_N$ for three "
                   "designs.", width="70%")
        doc.text(_solve_summary(name, lm))


def _indices_rows(pub: pd.DataFrame, unit: str, studies: list[StudyArtefacts]) -> list[list[str]]:
    """Per parameter: the paper's published indices, then each study's exact ones."""
    exact = [exact_sobol(s.drive(unit).sobol) for s in studies]
    rows = []
    for p in PARAMETERS:
        row = [math_label(p)]
        for idx in ("S1", "ST"):
            v = pub[(pub.unit == unit) & (pub.statistic == f"sobol_{idx}") & (pub.parameter == p)]["value"]
            row.append(fmt(float(v.iloc[0])) if len(v) else "–")
        for ex in exact:
            row += [fmt(ex.loc[p, "S1"]), fmt(ex.loc[p, "ST"])]
        rows.append(row)
    return rows


_BOUNDS_WORDS = {"table3": "the paper's Table 3 bounds", "design_range": "the range its designs span"}


def indices_vs_paper_section(doc: Document, units: list[str], data_dir, studies: list[StudyArtefacts],
                             level: int = 1) -> None:
    """Every study's exact Sobol' indices, Spearman ρ and surrogate quality beside the paper's.

    Parameters
    ----------
    doc
        The document to add to.
    units
        The drives shown; every study must have them.
    data_dir
        The paper's tables (config ``paper_data``), with its published statistics.
    studies
        The studies compared, in column order.
    level
        Heading level of the section.
    """
    pub = load_published(data_dir)
    doc.heading("Sensitivity: our FE studies beside the paper", level)
    doc.text("The indices of a surrogate hold over the bounds it is integrated over, and the studies' differ: "
             + "; ".join(f"{lit(study.name)} over {_BOUNDS_WORDS.get(b, lit(b))}"
                         for study in studies for b in {read_json(study.drive(units[0]).surrogate)["bounds_source"]})
             + ". Part of a difference between columns is the range, not the model: the paper's designs leave part "
             "of Table 3’s ranges empty (Part I, Designs: the least-covered input), and an input whose range is cut "
             "weighs less.")
    for u in units:
        heads = ["param.", "published $S_i$", "published $S_(T i)$"]   # the study "paper" is ours on its data
        for study in studies:
            heads += [f"{lit(study.name)} $S_i$", f"{lit(study.name)} $S_(T i)$"]
        doc.table(heads, _indices_rows(pub, u, studies),
                  f"{UNIT_NAMES[u]}: exact Sobol' indices of each study's quadratic surrogate beside the "
                  "paper's published values.")
        rows = []
        for study in studies:
            drive = study.drive(u)
            corr = pd.read_parquet(drive.correlation).set_index("parameter")
            s = read_json(drive.surrogate)
            rows.append([lit(study.name), *[fmt(corr.loc[p, "spearman_rho"], 3) for p in PARAMETERS],
                         fmt(s["r2"], 4), fmt(s["q2_loo"], 4)])
        doc.table(["study", *[f"$rho$ {math_label(p)}" for p in PARAMETERS], "surrogate $R^2$", "$Q^2_\"LOO\"$"],
                  rows, f"{UNIT_NAMES[u]}: Spearman $rho$ of each input with $Phi$ and surrogate quality per study.")


def fe_part(doc: Document, report: ReportInputs, tmp: Path) -> None:
    """Part II: the FE model, its convergence and curves, agreement with the paper, then each FE study.

    Parameters
    ----------
    doc
        The document to add to.
    report
        What the report shows; it must have at least one FE study.
    tmp
        A scratch folder for the figures drawn here; it must outlive ``doc.compile``.
    """
    paper_studies, fe_studies = report.paper_studies, report.fe_studies
    doc.heading("Part II — our FE model", 1)
    pictures = {UNIT_NAMES[d.unit]: d.deformed_png for s in report.studies for d in s.drives if d.deformed_png}
    fe_model_section(doc, report.assumptions, pictures, report.fe_settings, 2)
    for study in fe_studies:
        if any(d.convergence for d in study.drives):
            convergence_section(doc, study, 2)
    curves_section(doc, fe_studies[0], tmp, 2)  # curves of one study are enough to show the test
    at_paper = [s for s in fe_studies if s.designs == "paper"]
    if at_paper and paper_studies:
        units = [u for u in at_paper[0].units if u in paper_studies[0].units]
        mesh_changes = fe_mesh_changes(fe_studies)
        agreement_section(doc, units, paper_studies[0], at_paper[0], tmp, report.fe_settings, 2, mesh_changes)
        knee_section(doc, units, report.data_dir, paper_studies[0], at_paper[0], tmp, 2)
        rank_split_section(doc, units, report.data_dir, paper_studies[0], at_paper[0],
                           AGREEMENT_TARGETS["spearman"], 2)
        catalogue_section(doc, units, paper_studies[0], fe_studies, report.fe_settings, 2)
    all_units = sorted({u for s in fe_studies for u in s.units}, key=["hd42", "hd120"].index)
    indices_vs_paper_section(doc, all_units, report.data_dir, paper_studies + fe_studies, 2)
    for study in fe_studies:
        doc.pagebreak()
        doc.heading(f"Study '{study.name}'", 2)
        correlation_section(doc, study, 3)
        surrogate_section(doc, study, 3)
        sobol_section(doc, study, 3)
