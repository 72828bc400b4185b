"""Rule fe_refined_solve: one design at another mesh refinement -> one row."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe_solve import DesignJob, refined_solve_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_refined_solve", study="fe", unit="hd42", design="hd42-lhs-01", ref="1.25")

prov = setup(snakemake)
w, p = snakemake.wildcards, snakemake.params
job = DesignJob(snakemake.input[0], w.design, w.unit, dict(p.settings), p.steps_per_ramp, dict(p.effects))
row = refined_solve_stage(job, snakemake.output[0], prov)
logging.info("%s", row)
