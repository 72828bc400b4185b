"""Part II of the report, our FE model against the paper's FEA at the paper's own design points:
level, rank, shape and offset slope per drive, held against the targets of issue 15, and how far
the measured mesh scatter alone moves each figure."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from hdwf.report.artefacts import FeSettings, StudyArtefacts
from hdwf.report.document import UNIT_NAMES, Document, fmt, unit_suffix
from hdwf.report.figures import agreement_figure
from hdwf.study.agreement import Agreement, ScatterBand, agreement, agreement_under_mesh_scatter
from hdwf.study.knee import offset_slope_weights
from hdwf.validation.effects import get as get_effect


def effects_text(effects) -> str:
    """``{name: {parameter: value}}`` in words: each effect's title and its parameter values."""
    def value(name, p, v):
        unit = get_effect(name).param(p).unit
        unit = unit + "s" if unit == "module" and v != 1 else unit
        return f"{v:g}{unit_suffix(unit)} (`{p}`)"
    return "; ".join(f"{get_effect(name).title.lower()}: " + ", ".join(value(name, p, v) for p, v in params.items())
                     for name, params in effects.items())


#: What "agrees with the paper" means here (issue 15; docs/fe-model.md): level, rank, shape and the
#: offset slope dΦ/dr_FS, ours over the paper's
AGREEMENT_TARGETS = {"median_ratio": (0.67, 1.5), "spearman": 0.9, "r2": 0.8, "slope_ratio": (0.5, 2.0)}
#: a target met in fewer than this share of the mesh-scatter draws is said to be at risk
AT_RISK_SHARE = 0.95
#: each target as the closed interval [low, high] its figure must lie in
TARGET_BOUNDS = {figure: target if isinstance(target, tuple) else (target, np.inf)
                 for figure, target in AGREEMENT_TARGETS.items()}


def _target_checks(name: str, a: Agreement, slope_ratio: float, band: ScatterBand | None = None
                   ) -> tuple[list[str], list[str]]:
    """The targets missed, and those met in fewer than 95 % of the mesh-scatter draws (with ``band``);
    each says in what share of the draws it is met."""
    lo, hi = AGREEMENT_TARGETS["median_ratio"]
    s_lo, s_hi = AGREEMENT_TARGETS["slope_ratio"]
    checks = [("median_ratio", "median ratio", a.median_ratio, f"{fmt(a.median_ratio, 2)} outside [{lo}, {hi}]"),
              ("spearman", "Spearman", a.spearman, f"{fmt(a.spearman)} < {AGREEMENT_TARGETS['spearman']}"),
              ("r2", "$R^2$", a.r2, f"{fmt(a.r2)} < {AGREEMENT_TARGETS['r2']}"),
              ("slope_ratio", "$d Phi slash d r_\"FS\"$", slope_ratio,
               f"{fmt(slope_ratio, 2)}× the paper's, outside [{s_lo}, {s_hi:g}]×")]
    missed, at_risk = [], []
    for figure, label, value, how in checks:
        low, high = TARGET_BOUNDS[figure]
        share = _draw_share(figure, band)
        said = "" if share is None else _share_said(share)
        if not low <= value <= high:
            missed.append(f"{name}: {label} {how}{said}")
        elif share is not None and share < AT_RISK_SHARE:
            at_risk.append(f"{name}: {label}{said}")
    return missed, at_risk


def _share_said(share: float) -> str:
    return f" (met in {share * 100:.1f} % of the mesh-scatter draws)"


def _draw_share(figure: str, band: ScatterBand | None) -> float | None:
    """The share of the mesh-scatter draws in which ``figure`` meets its target, without a band None."""
    if band is None or figure not in band.samples:
        return None
    return band.share(figure, *TARGET_BOUNDS[figure])


def _scatter_table(doc: Document, rows: list[list[str]]) -> None:
    doc.text("How far the mesh alone moves these figures: each of our $Phi$ is moved by a relative change drawn "
             "from the mesh changes measured on the same drive (the designs of the mesh-convergence study, default mesh against "
             "1.25× finer; Mesh convergence above) with a random sign, 2000 times (seeded). A target met in "
             "some draws and missed in others could be met or missed by mesh scatter of that size alone; the "
             "verdict below gives, for each target missed or met in fewer than 95 % of the draws, the share of draws "
             "that meet it. "
             "The bands are a lower bound on what the mesh can do: the change at 1.25× understates the default "
             "mesh's error (docs/fe-model.md, Mesh convergence: against meshes up to 3× finer the default mesh's "
             "$Phi$ lies 1–12 % high on the eight designs measured), and an error common to all designs moves "
             "the level, not the rank.")
    doc.table(["drive", "mesh change", "median ratio", "Spearman $rho$", "$R^2$",
               "$d Phi slash d r_\"FS\"$ ours/paper"], rows,
              "The agreement figures under the measured mesh scatter, 5–95 % of the draws (mesh change: median "
              "and largest measured; `hdwf.study.agreement`).")


def _verdict_text(misses: list[str], at_risk: list[str]) -> str:
    lo, hi = AGREEMENT_TARGETS["median_ratio"]
    s_lo, s_hi = AGREEMENT_TARGETS["slope_ratio"]
    return (f"Targets (level, rank, shape, offset slope): median ratio within [{lo}, {hi}], Spearman $rho >= "
            f"{AGREEMENT_TARGETS['spearman']}$, $R^2 >= {AGREEMENT_TARGETS['r2']}$, least-squares "
            f"$d Phi slash d r_\"FS\"$ within [{s_lo}, {s_hi:g}]× the paper's. "
            + ("Missed: " + "; ".join(misses) + "." if misses else "All met.")
            + (" Met, but not in 95 % of the mesh-scatter draws: " + "; ".join(at_risk) + "." if at_risk else ""))


@dataclass(frozen=True)
class PaperAgreement:
    """One drive of an FE study at the paper's design points against the paper's Φ: both values
    where both exist (``both``: columns ``paper``, ``ours``), their level, rank and shape
    (``figures``), and the least-squares dΦ/dr_FS, ours over the paper's (``slope_ratio``, with the
    weights that give it)."""

    paper_all: pd.Series
    ours_all: pd.Series
    both: pd.DataFrame
    figures: Agreement
    slope_weights: np.ndarray
    slope_ratio: float


def paper_agreement(paper: StudyArtefacts, ours: StudyArtefacts, unit: str) -> PaperAgreement:
    """``ours`` (an FE study at the paper's designs) against ``paper`` for one drive."""
    theirs = pd.read_parquet(paper.drive(unit).lost_motion).set_index("design_id")["lost_motion_arcmin"]
    our_table = pd.read_parquet(ours.drive(unit).lost_motion).set_index("design_id")
    mine = our_table["lost_motion_arcmin"]
    both = pd.concat({"paper": theirs, "ours": mine}, axis=1).dropna()
    weights = offset_slope_weights(our_table.loc[both.index])["rFS_mm"]
    slope_ratio = float((weights @ both["ours"].to_numpy()) / (weights @ both["paper"].to_numpy()))
    return PaperAgreement(theirs, mine, both, agreement(both["paper"], both["ours"]), weights, slope_ratio)


def mesh_scatter(pa: PaperAgreement, convergence) -> tuple[pd.Series, ScatterBand]:
    """The drive's measured mesh changes (a ``convergence.parquet``) and the band of ``pa``'s
    figures under scatter of that size (``hdwf.study.agreement.agreement_under_mesh_scatter``)."""
    changes = pd.read_parquet(convergence)["rel_change_fine"]
    return changes, agreement_under_mesh_scatter(pa.both["paper"], pa.both["ours"], changes,
                                                 slope_weights=pa.slope_weights)


def at_risk_note(figure: str, value: float, band: ScatterBand | None) -> str:
    """' (met in 60.6 % of the mesh-scatter draws)' for a met target that fewer than
    ``AT_RISK_SHARE`` of the draws meet, else ''."""
    low, high = TARGET_BOUNDS[figure]
    share = _draw_share(figure, band)
    if share is None or not low <= value <= high or share >= AT_RISK_SHARE:
        return ""
    return _share_said(share)


def fe_mesh_changes(fe_studies) -> dict[str, Path]:
    """Per drive, the ``convergence.parquet`` of the FE study that has one: its measured mesh changes."""
    return {d.unit: d.convergence for s in fe_studies for d in s.drives if d.convergence}


def drive_role(settings: FeSettings | None, unit: str) -> str:
    """' (calibrated)' or ' (blind)' when the FE effects were set on one drive's data, else ''."""
    if not (settings and settings.effects and settings.calibrated_on):
        return ""
    return " (calibrated)" if unit == settings.calibrated_on else " (blind)"


def agreement_section(doc: Document, units: list[str], paper: StudyArtefacts, ours: StudyArtefacts, tmp: Path,
                      settings: FeSettings | None = None, level: int = 1,
                      mesh_changes: dict[str, Path] | None = None) -> None:
    """Our lost motion against the paper's FEA at the same design points: table and figure.

    Parameters
    ----------
    doc
        The document to add to.
    units
        The drives both studies have.
    paper
        The study on the paper's tables.
    ours
        The FE study at the paper's design points.
    tmp
        A scratch folder for the figure; it must outlive ``doc.compile``.
    settings
        The FE settings: with effects calibrated on one drive, the rows say which is calibrated and
        which blind.
    level
        Heading level of the section.
    mesh_changes
        Per drive, a ``convergence.parquet`` of the same model: its measured mesh changes give the
        band of each figure under mesh scatter (``hdwf.study.agreement``).
    """
    doc.heading("Our FE against the paper's FEA at its own design points", level)
    effects = settings.effects if settings else {}
    rows, pairs, misses, at_risk, scatter_rows = [], {}, [], [], []
    for u in units:
        pa = paper_agreement(paper, ours, u)
        both, a, slope_ratio, weights, mine = pa.both, pa.figures, pa.slope_ratio, pa.slope_weights, pa.ours_all
        ratio = both["ours"] / both["paper"]
        pairs[UNIT_NAMES[u]] = (pa.paper_all.reindex(mine.index).to_numpy(float), mine.to_numpy(float))
        role = drive_role(settings, u)
        band = None
        if mesh_changes and mesh_changes.get(u):
            changes, band = mesh_scatter(pa, mesh_changes[u])
            scatter_rows.append([UNIT_NAMES[u] + role, f"{fmt(changes.abs().median() * 100, 2)} %, {fmt(changes.abs().max() * 100, 1)} %",
                                 *(f"{fmt(lo, 3)}–{fmt(hi, 3)}" for lo, hi in (band.median_ratio, band.spearman, band.r2)),
                                 f"{fmt(slope_ratio, 2)}× ({fmt(band.slope_ratio[0], 2)}–{fmt(band.slope_ratio[1], 2)}×)"])
        missed, risky = _target_checks(UNIT_NAMES[u] + role, a, slope_ratio, band)
        misses += missed
        at_risk += risky
        rows.append([UNIT_NAMES[u] + role, f"{len(both)} of {len(mine)}", fmt(a.spearman), fmt(a.spearman_p, 3), fmt(a.r2),
                     fmt(both["paper"].mean(), 3), fmt(both["ours"].mean(), 3), fmt(a.median_ratio, 2),
                     f"{fmt(ratio.min(), 2)}–{fmt(ratio.max(), 2)}"])
    doc.table(["drive", "designs solved", "Spearman $rho$", "p", "$R^2$", "paper mean $Phi$ (arcmin)", "our mean $Phi$ (arcmin)",
               "median ratio ours/paper", "ratio range"], rows,
              "Agreement of our $Phi$ with the paper's at the 27 design points of its Tables 4/5 ($R^2$ of a linear fit).")
    if scatter_rows:
        _scatter_table(doc, scatter_rows)
    path = tmp / "agreement.png"
    agreement_figure(pairs, "hdwf FE vs the paper's Ansys FEA, same 27 designs", path)
    doc.figure(path, "Our lost motion against the paper's at the same design points.",
               width="100%" if len(pairs) > 1 else "55%")
    verdict = _verdict_text(misses, at_risk)
    if effects:
        doc.text(f"Our model here: the section with {effects_text(effects)}. " + verdict + " The knee below "
                 "shows where the shape parts: the uniform 2D section either holds the teeth preloaded or has "
                 "lost them, where the paper's 3D cup loses its engagement gradually.")
    else:
        doc.text("The ranking is what the study needs (which parameters matter). " + verdict + " The bare 2D section "
                 "has rigid-body flank backlash from $r_\"FS\"$, $r_\"CS\"$ with no preload to take it up; the "
                 "paper's 3D model evidently takes most of it up. The campaigns `paper_hd42` and `paper_hd120` of "
                 "Part III search for the effect that does, and the knee below shows what is left.")
