"""Rule full_report: every study's and campaign's artefacts -> results/report.pdf."""
import logging

from _helpers import folder_of, mock_snakemake, setup

from hdwf.stages.report import full_report_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("full_report")

prov = setup(snakemake)
p = snakemake.params
artefacts = dict(snakemake.input.items())
data_dir = folder_of(artefacts.pop("paper_data"))
pdf = full_report_stage(p.studies, p.fe_settings, artefacts, p.owners, data_dir, prov, snakemake.output[0])
logging.info("wrote %s", pdf)
