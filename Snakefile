# hdwf: the lost-motion study of harmonic drives, from design of experiments to a PDF report.
# Targets: default (`all`): every study through results/report.pdf (and the paper study's own PDF);
# `paper`: the statistics chain on the paper's Tables 4/5 -> results/paper/report.pdf;
# `fe_studies`: the FE studies' artefacts without the report.
# Rules live in workflow/rules/*.smk; scripts in workflow/scripts/ are thin adapters over the
# installed `hdwf` package (pip install -e .).

import os
from pathlib import Path

from snakemake.utils import min_version

from hdwf.config import SCHEMA_PATH, validate_config
from hdwf.validation.measurements import SPECIMEN_ID_PATTERN

min_version("9.0")

# glibc maps blocks above a threshold (128 kB at start) straight from the OS, unmaps them when
# freed and trims the heap's top; the next array is then faulted in page by page, and a solve
# allocates such temporaries thousands of times. Kept in the heap, two study jobs at once took
# 7.7 % less time, with results the same to the last bit (docs/fe-model.md, Time). glibc reads
# these when a process starts, so they are set here, for the jobs. Each one already in the
# environment wins; HDWF_KEEP_FREED_MEMORY=0 (only "0") leaves glibc's own handling.
if os.environ.get("HDWF_KEEP_FREED_MEMORY", "1") != "0":
    for _name, _value in {"MALLOC_MMAP_THRESHOLD_": "33554432", "MALLOC_TRIM_THRESHOLD_": "4294967296",
                          "MALLOC_TOP_PAD_": "268435456"}.items():
        os.environ.setdefault(_name, _value)

report: "workflow/report/workflow.rst"

configfile: "config.yaml"

# Fail at start-up, naming the key, before any job runs.
# With --configfile, a problem is blamed on the last file that sets the key.
validate_config(config, SCHEMA_PATH,
                source=[*(["config.yaml"] if Path("config.yaml").exists() else []), *workflow.overwrite_configfiles])

include: "workflow/rules/common.smk"

wildcard_constraints:
    unit="hd42|hd120",
    study=_alternatives(list(STUDIES)),
    design=r"[A-Za-z0-9_\-]+",
    ref=r"[0-9.]+",
    campaign=_alternatives(list(CAMPAIGNS)),
    specimen=SPECIMEN_ID_PATTERN,   # the ids the measurement loader accepts

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


rule fe_studies:
    input:
        fe_study_targets(),
