"""Rule validation_figures: measured vs predicted, residuals, the ladder."""
from _helpers import mock_snakemake, setup

from hdwf.stages.validation import figures_stage

if "snakemake" not in globals():  # run outside Snakemake, from the project root
    snakemake = mock_snakemake("validation_figures", campaign="demo")

prov = setup(snakemake)
inp, out = snakemake.input, snakemake.output
figures_stage(inp.diagnosis, inp.points, inp.ladder, out.measured, out.residuals, out.ladder, prov)
