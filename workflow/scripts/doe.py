"""Rule doe: Table 3 bounds -> optimal LHS (hdwf.stages.doe.doe_stage)."""
import logging

from _helpers import folder_of, mock_snakemake, setup

from hdwf.stages.doe import doe_stage
from hdwf.study.paper import table3_bounds

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("doe", unit="hd42")

prov = setup(snakemake)
unit = snakemake.wildcards.unit
bounds = table3_bounds(folder_of(snakemake.input.bounds), unit)   # the declared input, so an edit re-runs it
df = doe_stage(bounds, snakemake.params.n, snakemake.params.seed, snakemake.params.optimization,
               snakemake.output[0], prov, unit)
logging.info("wrote %d designs for %s", len(df), unit)
