"""The two reports, composed from the parts: ``study_report`` (a study on the paper's tables, its
own PDF) and ``full_report`` (Part I the paper's tables, Part II our FE model, Part III the model
against measurements). Each reads the artefacts it is given and writes only its PDF."""

from __future__ import annotations

import tempfile
from pathlib import Path

from hdwf.report.artefacts import ReportInputs, StudyArtefacts
from hdwf.report.document import UNIT_NAMES, Document
from hdwf.report.fe_part import fe_part
from hdwf.report.paper_part import (comparison_section, correlation_section, designs_section, inputs_section,
                                    paper_part, sobol_section, surrogate_section)
from hdwf.report.references import cite, references_section
from hdwf.report.summary_part import summary_section
from hdwf.report.validation_part import validation_part

_SUBTITLES = {"paper": "The statistics chain on the paper's own FEA tables (its Tables 4 and 5)"}


def study_report(study: StudyArtefacts, data_dir, provenance: dict, out) -> Path:
    """Typeset ``results/{study}/report.pdf`` from the study's artefacts.

    Parameters
    ----------
    study
        The study and its drives' artefacts.
    data_dir
        The paper's tables (config ``paper_data``).
    provenance
        The provenance printed under the title.
    out
        The PDF's path.

    Returns
    -------
    Path
        ``out``.
    """
    doc = Document(f"hdwf study '{study.name}': lost motion of harmonic drives",
                   _SUBTITLES.get(study.source, study.source), provenance)
    doc.text("This report reproduces the correlation, surrogate and global-sensitivity analysis of Hrcek et al., "
             f"*Global Sensitivity Analysis of Chosen Harmonic Drive Parameters Affecting Its Lost Motion* {cite('paper')}, for the "
             f"drives {', '.join(UNIT_NAMES[u] for u in study.units)}. Every number and figure below was computed "
             f"by the Snakemake workflow {cite('snakemake')} from the artefacts under `results/`; the provenance above identifies the "
             "configuration, code and packages.")
    inputs_section(doc, study.units, data_dir)
    designs_section(doc, study)
    doc.pagebreak()
    correlation_section(doc, study)
    doc.pagebreak()
    surrogate_section(doc, study)
    doc.pagebreak()
    sobol_section(doc, study)
    doc.pagebreak()
    comparison_section(doc, study, data_dir)
    references_section(doc)
    return doc.compile(out)


def full_report(report: ReportInputs, out) -> Path:
    """Typeset ``results/report.pdf``: the paper replication, then our FE model and its studies,
    then the model against measurements.

    Parameters
    ----------
    report
        Every study and campaign with their artefacts, and what the report quotes.
    out
        The PDF's path.

    Returns
    -------
    Path
        ``out``.
    """
    doc = Document("hdwf: lost motion of harmonic drives", "Paper replication, our FE model and its studies",
                   report.provenance)
    doc.text("Part I reproduces the statistics of Hrcek et al., _Global Sensitivity Analysis of Chosen "
             f"Harmonic Drive Parameters Affecting Its Lost Motion_ {cite('paper')}, from their own FEA tables; Part II solves the same "
             "lost-motion test with our FE model, at our own optimal Latin hypercube (`fe`) and at the paper's design "
             "points (`fe_at_paper`), and runs the same chain on it; Part III holds the model against measurement "
             "files, finds which physical effect it misses and re-solves it with that effect. Every number below "
             f"was computed by the Snakemake workflow {cite('snakemake')} from the artefacts under `results/`.")
    doc.text("Symbols: the flexspline (FS) is twisted against the held circular spline (CS) to ±T, 4 % of the "
             "rated torque $T_N$ (the paper's Table 1); $phi$ and $phi'$ are the twist magnitudes at +T and −T "
             "and the lost motion is $Phi = phi + phi'$. The five inputs: $d$ and $D$, the bore and outside "
             "diameter of the wave generator's (WG's) bearing; $G_r$, its radial clearance; $r_\"FS\"$ and "
             "$r_\"CS\"$, the normal offsets that thin the FS teeth and widen the CS spaces. A module m is the "
             "gear module (0.18 mm on HD 42, 0.514 mm on HD 120); a preload or layer given in m is in modules.")
    summary_section(doc, report)
    # Figures drawn here (not by a rule) live until the document is typeset.
    with tempfile.TemporaryDirectory(prefix="hdwf-figs-") as tmp:
        for study in report.paper_studies:
            paper_part(doc, study, report.data_dir)
        if report.fe_studies:
            fe_part(doc, report, Path(tmp))
        if report.campaigns:
            validation_part(doc, report.campaigns, report.fe_settings.mesh, report.fe_settings.effects)
        references_section(doc)
        return doc.compile(out)
