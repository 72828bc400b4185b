# The PDF reports, typeset with typst from the artefacts only (hdwf.stages.report, hdwf.report).
# Each report rule has one named input per kind of artefact, a list of paths, and the parameter
# `owners`: the same names with, per path, whose artefact it is ([study, unit] or [campaign]).

# What the reports read of each drive of a study: kind -> file under results/{study}/{unit}/.
DRIVE_ARTEFACTS = {
    "lost_motion": "lost_motion.parquet",
    "correlation": "correlation.parquet",
    "correlation_png": "correlation.png",
    "surrogate": "surrogate.json",
    "surrogate_png": "surrogate.png",
    "sobol": "sobol.parquet",
    "sobol_png": "sobol_convergence.png",
}
# What the full report reads of each campaign: kind -> file under results/validation/{campaign}/.
CAMPAIGN_ARTEFACTS = {
    "diagnosis": "diagnosis.json",
    "ladder": "ladder.parquet",
    "measured_png": "measured_vs_predicted.png",
    "residuals_png": "residuals.png",
    "ladder_png": "ladder.png",
}


def study_entries(study, fe_parts):
    """(kind, owner, path) of each artefact of the study; with `fe_parts` also what Part II shows."""
    for unit in study_units(study):
        owner = [study, unit]
        for kind, name in DRIVE_ARTEFACTS.items():
            yield kind, owner, f"results/{study}/{unit}/{name}"
        yield "doe", owner, f"results/doe/{unit}/designs.parquet"
        if not fe_parts:
            continue
        if STUDIES[study]["source"] == "fe":
            yield "curves", owner, f"results/{study}/{unit}/curves.parquet"
        if study == FE["convergence"]["study"]:
            yield "convergence", owner, f"results/{study}/{unit}/convergence.parquet"
        if study == FE["picture"]["study"]:
            yield "deformed_png", owner, f"results/{study}/{unit}/deformed_{FE['picture']['design']}.png"


def campaign_entries(campaign):
    for kind, name in CAMPAIGN_ARTEFACTS.items():
        yield kind, [campaign], f"results/validation/{campaign}/{name}"


def named_inputs(entries):
    """Entries -> the named inputs (kind -> paths) and the owners (kind -> owner per path)."""
    files, owners = {}, {}
    for kind, owner, path in entries:
        files.setdefault(kind, []).append(path)
        owners.setdefault(kind, []).append(owner)
    return files, owners


def study_report_files(wildcards):
    return named_inputs(study_entries(wildcards.study, fe_parts=False))


def full_report_files():
    entries = [e for study in STUDIES for e in study_entries(study, fe_parts=True)]
    entries += [e for campaign in CAMPAIGNS for e in campaign_entries(campaign)]
    return named_inputs(entries)


rule study_report:
    input:
        unpack(lambda w: study_report_files(w)[0]),
    output:
        "results/{study}/report.pdf",
    params:
        owners=lambda w: study_report_files(w)[1],
        study_config=lambda w: STUDIES[w.study],
        data_dir=config["paper_data"],
    log:
        "results/logs/{study}_report.log",
    script:
        "../scripts/report.py"


rule full_report:
    input:
        unpack(lambda w: full_report_files()[0]),
    output:
        "results/report.pdf",
    params:
        owners=lambda w: full_report_files()[1],
        studies=STUDIES,
        fe_settings={k: v for k, v in FE.items() if k not in ("convergence", "picture")},
        data_dir=config["paper_data"],
    log:
        "results/logs/report.log",
    script:
        "../scripts/full_report.py"
