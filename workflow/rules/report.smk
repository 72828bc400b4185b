# The study's PDF report, typeset with typst from the artefacts only.

# Per-drive artefacts the report reads, keyed as hdwf.report.document expects them ("<unit>__<key>").
REPORT_ARTEFACTS = {
    "lost_motion": "lost_motion.parquet",
    "correlation": "correlation.parquet",
    "correlation_png": "correlation.png",
    "surrogate": "surrogate.json",
    "surrogate_png": "surrogate.png",
    "sobol": "sobol.parquet",
    "sobol_png": "sobol_convergence.png",
}


def report_inputs(wildcards):
    units = study_units(wildcards.study)
    files = {}
    for unit in units:
        for key, name in REPORT_ARTEFACTS.items():
            files[f"{unit}__{key}"] = f"results/{wildcards.study}/{unit}/{name}"
        files[f"{unit}__doe"] = f"results/doe/{unit}/designs.parquet"
    return files


rule study_report:
    input:
        unpack(report_inputs),
    output:
        "results/{study}/report.pdf",
    params:
        units=lambda w: study_units(w.study),
        study_config=lambda w: STUDIES[w.study],
        data_dir=config["paper_data"],
        repo=REPO_DIR,
    log:
        "results/logs/{study}_report.log",
    script:
        "../scripts/report.py"


def full_report_inputs(wildcards):
    files = {}
    for study in STUDIES:
        for unit in study_units(study):
            for key, name in REPORT_ARTEFACTS.items():
                files[f"{study}__{unit}__{key}"] = f"results/{study}/{unit}/{name}"
            files[f"{study}__{unit}__doe"] = f"results/doe/{unit}/designs.parquet"
            if STUDIES[study]["source"] == "fe":
                files[f"{study}__{unit}__curves"] = f"results/{study}/{unit}/curves.parquet"
            if study == FE["convergence"]["study"]:
                files[f"{study}__{unit}__convergence"] = f"results/{study}/{unit}/convergence.parquet"
            if study == FE["picture"]["study"]:
                files[f"{study}__{unit}__deformed_png"] = f"results/{study}/{unit}/deformed_{FE['picture']['design']}.png"
    for c in CAMPAIGNS:
        base = f"results/validation/{c}"
        files.update({f"validation__{c}__diagnosis": f"{base}/diagnosis.json",
                      f"validation__{c}__ladder": f"{base}/ladder.parquet",
                      f"validation__{c}__measured_png": f"{base}/measured_vs_predicted.png",
                      f"validation__{c}__residuals_png": f"{base}/residuals.png",
                      f"validation__{c}__ladder_png": f"{base}/ladder.png"})
    return files


rule full_report:
    input:
        unpack(full_report_inputs),
    output:
        "results/report.pdf",
    params:
        studies=STUDIES,
        fe_settings={k: v for k, v in FE.items() if k not in ("convergence", "picture")},
        campaigns=list(CAMPAIGNS),
        data_dir=config["paper_data"],
        repo=REPO_DIR,
    log:
        "results/logs/report.log",
    script:
        "../scripts/full_report.py"
