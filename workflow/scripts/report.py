"""Rule study_report: a study's artefacts -> results/{study}/report.pdf."""
import logging

from _helpers import folder_of, mock_snakemake, setup

from hdwf.stages.report import study_report_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("study_report", study="paper")

prov = setup(snakemake)
p = snakemake.params
artefacts = dict(snakemake.input.items())
data_dir = folder_of(artefacts.pop("paper_data"))
pdf = study_report_stage(snakemake.wildcards.study, p.study_config, artefacts, p.owners, data_dir, prov,
                         snakemake.output[0])
logging.info("wrote %s", pdf)
