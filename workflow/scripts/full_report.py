"""Rule full_report: every study's and campaign's artefacts -> results/report.pdf."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.report import full_report_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("full_report")

prov = setup(snakemake)
p = snakemake.params
pdf = full_report_stage(p.studies, p.fe_settings, dict(snakemake.input.items()), p.owners, p.data_dir, prov,
                        snakemake.output[0])
logging.info("wrote %s", pdf)
