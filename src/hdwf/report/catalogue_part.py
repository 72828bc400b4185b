"""Part II of the report: the lost motion of our model and the paper's against makers' catalogues
(``hdwf.study.catalogue``): the elastic Φ = 2T/K1 of a real unit of the same size."""

from __future__ import annotations

import pandas as pd

from hdwf.drive.geometry import unit_data
from hdwf.report.agreement_part import drive_role
from hdwf.report.artefacts import FeSettings, StudyArtefacts
from hdwf.report.document import UNIT_NAMES, Document, fmt
from hdwf.report.references import cite
from hdwf.study.catalogue import LIMITS, CatalogueCheck, catalogue_check, catalogue_units, size_ratio


def _lost_motion(study: StudyArtefacts, unit: str) -> pd.Series:
    table = pd.read_parquet(study.drive(unit).lost_motion)
    return table["lost_motion_arcmin"]


def span_text(lo: float, hi: float, digits: int) -> str:
    """``lo–hi``, or one number where the two print alike (a drive compared with one unit)."""
    return fmt(lo, digits) if f"{lo:.{digits}f}" == f"{hi:.{digits}f}" else f"{fmt(lo, digits)}–{fmt(hi, digits)}"


def _with_ratio(check: CatalogueCheck, name: str) -> str:
    return f"{fmt(check.levels_arcmin[name], 3)} ({span_text(*check.ratio(name), 2)}×)"


def catalogue_checks(units: list[str], paper: StudyArtefacts, fe_studies: list[StudyArtefacts]
                     ) -> dict[str, CatalogueCheck]:
    """Per drive, the paper's median Φ (level ``paper``) and each FE study's (by its name) against
    the catalogue units it compares with."""
    checks = {}
    for u in units:
        values = {"paper": _lost_motion(paper, u)} | {s.name: _lost_motion(s, u) for s in fe_studies if u in s.units}
        checks[u] = catalogue_check(u, unit_data(u).torque_Nmm / 1000.0, values)
    return checks


def catalogue_phi_text(check: CatalogueCheck) -> str:
    """The compared units and their 2T/K1, e.g. ``CSF-17: 0.815 arcmin``."""
    units = " and ".join(f"CSF-{size}" for size in check.sizes)
    return f"{units}: {span_text(*check.catalogue_phi_arcmin, 3)} arcmin"


def catalogue_section(doc: Document, units: list[str], paper: StudyArtefacts, fe_studies: list[StudyArtefacts],
                      settings: FeSettings | None = None, level: int = 2) -> None:
    """Median Φ of the paper's tables and of each FE study against the catalogue units' 2T/K1."""
    doc.heading("Against makers' catalogues", level)
    levels = {"paper": "the paper's FEA"} | {s.name: f"ours, `{s.name}`" for s in fe_studies}
    checks, rows = catalogue_checks(units, paper, fe_studies), []
    for u in units:
        check = checks[u]
        rows.append([UNIT_NAMES[u] + drive_role(settings, u),
                     ", ".join(f"{c.series}-{c.size}: {c.k1_Nm_per_rad / 1e4:g}" for c in catalogue_units(u)),
                     span_text(*check.catalogue_phi_arcmin, 3),
                     *(_with_ratio(check, name) if name in check.levels_arcmin else "–" for name in levels)])
    doc.table(["drive", "catalogue $K_1$ ($10^4$ N·m/rad)", "catalogue $2T slash K_1$",
               *(f"median $Phi$, {label} (over the catalogue's)" for label in levels.values())], rows,
              "Elastic lost motion at ±T of a real unit of the same size, $2T slash K_1$ (arcmin; Harmonic Drive "
              f"CSF {cite('catalogue')}, ratio 50; ±T lies below $T_1$), against the median $Phi$ of each set of designs.")
    text = ("A catalogue unit is measured whole, cup, diaphragm, bearing and teeth, by its maker: no model of ours "
            "or the paper's made these numbers. Its backlash and hysteresis (of the order of an arcminute at $T_N$) "
            "are left out here, so $2T slash K_1$ is the part a frictionless model should give. Two limits "
            f"of this check: {LIMITS}.")
    if "hd42" in checks and "hd120" in checks:
        small, large = checks["hd42"], checks["hd120"]
        c_lo, c_hi = size_ratio(small, large)
        said = [f"the catalogue {fmt(c_lo, 2)}–{fmt(c_hi, 2)}"]
        said += [f"{label} {fmt(size_ratio(small, large, name)[0], 2)}" for name, label in levels.items()
                 if name in small.levels_arcmin and name in large.levels_arcmin]
        text += (" Torque and stiffness both grow with the size cubed, so both drives should show about the same "
                 "lost motion in arcmin. The median $Phi$ of HD 120 over that of HD 42: " + "; ".join(said) + ".")
        text += _blind_sentence(small, large, settings)
    doc.text(text)


def _blind_sentence(small: CatalogueCheck, large: CatalogueCheck, settings: FeSettings | None) -> str:
    """Where the paper's two drives leave the size law and a study calibrated on one keeps nearer it,
    the blind drive's miss of the paper's level is that departure; say so with the numbers."""
    if not (settings and settings.effects and settings.calibrated_on):
        return ""
    c_lo, c_hi = size_ratio(small, large)
    away = {name: max(c_lo / r, r / c_hi, 1.0) for name in small.levels_arcmin if name in large.levels_arcmin
            for r in [size_ratio(small, large, name)[0]]}
    ours = [n for n in away if n != "paper"]
    if "paper" not in away or away["paper"] <= 1.0 or not ours or max(away[n] for n in ours) >= away["paper"]:
        return ""
    blind = UNIT_NAMES["hd120" if settings.calibrated_on == "hd42" else "hd42"]
    return (f" The paper's two drives lie {fmt(away['paper'], 2)}× off the catalogue's ratio, ours at most "
            f"{fmt(max(away[n] for n in ours), 2)}×: calibrated on the {UNIT_NAMES[settings.calibrated_on]} table, our "
            f"model carries that calibration to {blind} closer to the size law than the paper's two tables keep it; "
            "so part of the blind drive's miss of the paper's level is the paper's own departure from that law "
            "(the table above sets each level against the real unit's).")
