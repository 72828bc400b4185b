"""Rule fe_solve: one design -> its mesh (.msh, for review), lost-motion row and torque–twist curve."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe_solve import DesignJob, DesignOutputs, solve_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_solve", study="fe", unit="hd42", design="hd42-lhs-01")

prov = setup(snakemake)
w, p, out = snakemake.wildcards, snakemake.params, snakemake.output
job = DesignJob(snakemake.input[0], w.design, w.unit, dict(p.settings), p.steps_per_ramp, dict(p.effects))
row = solve_stage(job, DesignOutputs(out.msh, out.row, out.curve), prov)
logging.info("%s", row)
