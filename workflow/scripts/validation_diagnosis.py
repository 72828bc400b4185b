"""Rule validation_diagnosis: calibrate and rank the candidate effects."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.validation import CampaignInputs, CampaignPlan, diagnosis_stage

# guarded: the re-solves before a further round run in spawned processes, which import this file
if __name__ == "__main__":
    if "snakemake" not in globals():  # run outside Snakemake, from the project root
        snakemake = mock_snakemake("validation_diagnosis", campaign="demo")
    prov = setup(snakemake)
    result = diagnosis_stage(CampaignPlan(**snakemake.params.plan),
                             CampaignInputs(snakemake.input.measurements, list(snakemake.input.tables)),
                             snakemake.output.json, snakemake.output.points, prov, jobs=snakemake.threads)
    logging.info("verdict: %s", result["verdict"])
