"""Rule validation_ladder: the ladder's variants solved where the tables lack them, then RMSE,
bias and ΔBIC of every rung."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.validation import CampaignInputs, ladder_stage
from hdwf.validation.variants import SolveSetup

# guarded: the solves run in spawned processes, which import this file
if __name__ == "__main__":
    if "snakemake" not in globals():  # run outside Snakemake, from the project root
        snakemake = mock_snakemake("validation_ladder", campaign="demo")
    prov = setup(snakemake)
    p = snakemake.params
    ladder = ladder_stage(SolveSetup(p.unit, dict(p.settings), p.steps_per_ramp, snakemake.threads),
                          CampaignInputs(snakemake.input.measurements, list(snakemake.input.tables)),
                          snakemake.input.diagnosis, snakemake.output[0], prov)
    logging.info("\n%s", ladder.to_string())
