"""Rule fe_refined_solve: one design at another mesh refinement -> one row."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe_solve import refined_solve_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_refined_solve", study="fe", unit="hd42", design="hd42-lhs-01", ref="1.25")

prov = setup(snakemake)
w = snakemake.wildcards
row = refined_solve_stage(snakemake.input[0], w.design, w.unit, dict(snakemake.params.settings),
                          snakemake.params.steps_per_ramp, snakemake.output[0], prov,
                          effects=dict(snakemake.params.effects))
logging.info("%s", row)
