"""Rule correlation: lost_motion.parquet -> correlation.parquet + figure."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.report.document import UNIT_NAMES
from hdwf.stages.stats import correlation_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("correlation", study="paper", unit="hd42")

prov = setup(snakemake)
w = snakemake.wildcards
table = correlation_stage(snakemake.input[0], snakemake.output.table, snakemake.output.figure,
                          f"study '{w.study}', {UNIT_NAMES[w.unit]}: lost motion against each input", prov)
logging.info("\n%s", table.to_string())
