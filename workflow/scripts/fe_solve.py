"""Rule fe_solve: one design -> its mesh (.msh, for review), lost-motion row and torque–twist curve."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe_solve import DesignOutputs, solve_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_solve", study="fe", unit="hd42", design="hd42-lhs-01")

prov = setup(snakemake)
w, out = snakemake.wildcards, snakemake.output
row = solve_stage(snakemake.input[0], w.design, w.unit, dict(snakemake.params.settings),
                  snakemake.params.steps_per_ramp, DesignOutputs(out.msh, out.row, out.curve), prov,
                  effects=dict(snakemake.params.effects))
logging.info("%s", row)
