"""Rule study_report: a study's artefacts -> results/{study}/report.pdf."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.report import study_report_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("study_report", study="paper")

prov = setup(snakemake)
p = snakemake.params
pdf = study_report_stage(snakemake.wildcards.study, p.study_config, dict(snakemake.input.items()), p.owners,
                         p.data_dir, prov, snakemake.output[0])
logging.info("wrote %s", pdf)
