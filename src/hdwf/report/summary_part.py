"""The report's opening summary: the headline figure of each part, read from the same artefacts the
parts read, with the target or reference it is held against and the section that shows it in full.
It computes nothing the parts do not; it only gathers their conclusions on one page."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from hdwf.common.io import read_json
from hdwf.fe.hertz import ISO76_BALL_PRESSURE_MPA
from hdwf.report.agreement_part import (AGREEMENT_TARGETS, TARGET_BOUNDS, at_risk_note, drive_role,
                                        fe_mesh_changes, mesh_scatter, paper_agreement)
from hdwf.report.artefacts import CampaignArtefacts, ReportInputs
from hdwf.report.catalogue_part import catalogue_checks, catalogue_phi_text, span_text
from hdwf.report.document import UNIT_NAMES, Document, fmt, lit
from hdwf.report.paper_part import largest_sobol_difference
from hdwf.report.recovery_part import hidden_text, recovery_summary


@dataclass(frozen=True)
class Finding:
    """One row of the summary: what is measured, its value, what it is held against, whether it
    meets that (None where there is no target), and where it is shown."""

    what: str
    value: str
    against: str
    where: str
    met: bool | None = None


def _meets(figure: str, value: float) -> bool:
    low, high = TARGET_BOUNDS[figure]
    return bool(low <= value <= high)


def _replication(report: ReportInputs) -> list[Finding]:
    found = []
    for study in report.paper_studies:
        for unit, diff in largest_sobol_difference(study, report.data_dir).items():
            found.append(Finding(f"{UNIT_NAMES[unit]}: Sobol' indices of the paper's surrogate, largest "
                                 "difference from the published", fmt(diff, 4), "published (bounds unstated)",
                                 "Part I, Our figures against the paper's"))
    return found


def _fe_model(report: ReportInputs) -> list[Finding]:
    found = []
    for study in report.fe_studies:
        for drive in study.drives:
            if drive.convergence:
                conv = pd.read_parquet(drive.convergence)
                n_ok = int(conv["converged"].sum())
                change = conv["rel_change_fine"] * 100
                gci = (f"; median GCI {fmt(conv['gci_fine'].median() * 100, 1)} %"
                       if "gci_fine" in conv and conv["gci_fine"].notna().any() else "")
                found.append(Finding(f"{UNIT_NAMES[drive.unit]}: designs of `{study.name}` within 2 % on a 1.25× "
                                     "finer mesh (the change median and largest; the GCI of the representative "
                                     "designs, an error estimate)",
                                     f"{n_ok} of {len(conv)} (median {fmt(change.median(), 2)} %, largest "
                                     f"{fmt(change.max(), 2)} %{gci})", "all", "Part II, Mesh convergence",
                                     n_ok == len(conv)))
    at_paper = [s for s in report.fe_studies if s.designs == "paper"]
    if not (at_paper and report.paper_studies):
        return found
    lo, hi = AGREEMENT_TARGETS["median_ratio"]
    s_lo, s_hi = AGREEMENT_TARGETS["slope_ratio"]
    rho, r2 = AGREEMENT_TARGETS["spearman"], AGREEMENT_TARGETS["r2"]
    paper, ours = report.paper_studies[0], at_paper[0]
    mesh_changes = fe_mesh_changes(report.fe_studies)
    for unit in (u for u in ours.units if u in paper.units):
        pa = paper_agreement(paper, ours, unit)
        band = mesh_scatter(pa, mesh_changes[unit])[1] if mesh_changes.get(unit) else None
        name = UNIT_NAMES[unit] + drive_role(report.fe_settings, unit)
        where = "Part II, Our FE against the paper's FEA"
        a = pa.figures

        def finding(what: str, figure: str, value: float, shown: str, against: str) -> Finding:
            return Finding(f"{name}: {what}", shown + at_risk_note(figure, value, band), against, where,
                           _meets(figure, value))

        found += [finding("our $Phi$ over the paper's, median", "median_ratio", a.median_ratio,
                          fmt(a.median_ratio, 2), f"[{lo}, {hi}]"),
                  finding("Spearman $rho$, ours against the paper's", "spearman", a.spearman, fmt(a.spearman),
                          f"≥ {rho}"),
                  finding("$R^2$, ours against the paper's", "r2", a.r2, fmt(a.r2), f"≥ {r2}"),
                  finding("$d Phi slash d r_\"FS\"$, ours over the paper's", "slope_ratio", pa.slope_ratio,
                          f"{fmt(pa.slope_ratio, 2)}×", f"[{s_lo}, {s_hi:g}]×")]
        check = catalogue_checks([unit], paper, [ours])[unit]
        found.append(Finding(f"{name}: median $Phi$ over a catalogue unit's $2T slash K_1$ (the paper's in brackets)",
                             f"{span_text(*check.ratio(ours.name), 2)}× ({span_text(*check.ratio('paper'), 2)}×)",
                             catalogue_phi_text(check),
                             "Part II, Against makers' catalogues"))
    return found


def _over_rating(ladder: pd.DataFrame) -> str:
    """'; its last rung loads a ball above ISO 76's rating on 19 of 27 specimens' where it does."""
    last = ladder.iloc[-1]
    if not last.get("specimens_above_iso76", 0):
        return ""
    return (f"; its last rung loads a wave-generator ball above ISO 76’s {ISO76_BALL_PRESSURE_MPA:g} MPa on "
            f"{int(last['specimens_above_iso76'])} of {int(last['specimens_checked'])} specimens")


def _data_scale(campaign: CampaignArtefacts, last_rmse: float) -> str:
    """The measured values' RMS and the last rung's RMSE as a share of it: a fall of the error
    says little unless the error left is small against what was measured."""
    scale = campaign.measured_rms_arcmin()
    if scale is None:
        return ""
    share = f", the last rung {100 * last_rmse / scale:.2g} % of it" if np.isfinite(last_rmse) else ""
    return f"; the measured values' RMS {fmt(scale, 3)} arcmin{share}"


def _campaigns(report: ReportInputs) -> list[Finding]:
    found = []
    for campaign in report.campaigns:
        diag = read_json(campaign.diagnosis)
        ladder = pd.read_parquet(campaign.ladder)
        rmse = ladder["rmse_arcmin"].to_numpy(float)
        named = diag.get("verdict", {}).get("found_in_order") or []
        value = (f"{fmt(rmse[0], 3)} → {fmt(rmse[-1], 3)} arcmin ({fmt(rmse[0] / rmse[-1], 2)}×)"
                 if np.isfinite(rmse[[0, -1]]).all() else "a rung's solve failed: no fall to give")
        noise = diag.get("noise_arcmin")
        against = f"stated noise {fmt(noise, 3)} arcmin" if noise else "no noise stated"
        found.append(Finding(f"`{campaign.name}` ({UNIT_NAMES[diag['unit']]}): RMSE, bare model to the last rung; "
                             f"found {', '.join(lit(n) for n in named) if named else 'nothing'}"
                             + _over_rating(ladder), value, against + _data_scale(campaign, rmse[-1]),
                             f"Part III, Campaign '{lit(campaign.name)}'"))
        if diag.get("recovery"):
            found.append(Finding(f"`{campaign.name}` ({UNIT_NAMES[diag['unit']]}): the effects hidden in its "
                                 "synthetic data", recovery_summary(diag["recovery"]),
                                 f"hidden: {hidden_text(diag['hidden_effects'])}",
                                 f"Part III, Campaign '{lit(campaign.name)}'", diag["recovery"]["all_recovered"]))
    return found


def summary_section(doc: Document, report: ReportInputs, level: int = 1) -> None:
    """The headline figures of Parts I–III in one table (what the parts show in full).

    Parameters
    ----------
    doc
        The document to add to.
    report
        Every study and campaign the report shows.
    level
        Heading level of the section.
    """
    findings = _replication(report) + _fe_model(report) + _campaigns(report)
    if not findings:
        return
    doc.heading("At a glance", level, numbered=False)
    met = {True: "yes", False: "*no*", None: "–"}
    doc.table(["what", "value", "held against", "met", "shown in"],
              [[f.what, f.value, f.against, met[f.met], f.where] for f in findings],
              "The headline figure of each part, from the same artefacts as the part that shows it in full; "
              "the targets are those of the study (docs/fe-model.md), misses are explained where shown.",
              widths=["3fr", "1.5fr", "1.3fr", "0.5fr", "1.6fr"])
