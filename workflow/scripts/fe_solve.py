"""Rule fe_solve: one design's mesh -> its lost-motion row and torque–twist curve."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe import solve_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_solve", study="fe", unit="hd42", design="hd42-lhs-01")

prov = setup(snakemake)
w = snakemake.wildcards
row = solve_stage(snakemake.input.designs, w.design, w.unit, snakemake.input.mesh,
                  snakemake.params.steps_per_ramp, snakemake.output.row, snakemake.output.curve, prov,
                  effects=dict(snakemake.params.effects))
logging.info("%s", row)
