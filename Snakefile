# hdwf: the lost-motion study of harmonic drives, from design of experiments to a PDF report.
# Targets: default (`all`): every study through results/report.pdf (and the paper study's own PDF);
# `paper`: the statistics chain on the paper's Tables 4/5 -> results/paper/report.pdf;
# `fe_studies`: the FE studies' artefacts without the report.
# Rules live in workflow/rules/*.smk; scripts in workflow/scripts/ are thin adapters over the
# installed `hdwf` package (pip install -e .).

from snakemake.utils import min_version

from hdwf.config import SCHEMA_PATH, validate_config

min_version("9.0")

configfile: "config.yaml"

# Fail at start-up, naming the key, before any job runs.
validate_config(config, SCHEMA_PATH,
                source=(workflow.overwrite_configfiles or ["config.yaml"])[-1])

include: "workflow/rules/common.smk"
include: "workflow/rules/doe.smk"
include: "workflow/rules/paper.smk"
include: "workflow/rules/fe.smk"
include: "workflow/rules/stats.smk"
include: "workflow/rules/validation.smk"
include: "workflow/rules/report.smk"

# Jobs too small to wait in a cluster queue: on Slurm they run on the submitting host.
localrules: all, paper, fe_studies, validation, doe, fe_designs, paper_lost_motion, fe_aggregate, fe_convergence, correlation, surrogate, validation_figures, study_report, full_report


rule all:
    default_target: True
    input:
        "results/report.pdf",
        "results/paper/report.pdf",


rule paper:
    input:
        "results/paper/report.pdf",


def fe_study_targets():
    out = []
    for study in FE_STUDIES:
        for unit in study_units(study):
            out += [f"results/{study}/{unit}/{name}" for name in
                    ("lost_motion.parquet", "curves.parquet", "correlation.parquet", "surrogate.json", "sobol.parquet")]
    conv = FE["convergence"]["study"]
    out += [f"results/{conv}/{unit}/convergence.parquet" for unit in study_units(conv)]
    return out


rule fe_studies:
    input:
        fe_study_targets(),
