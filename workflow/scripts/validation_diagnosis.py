"""Adapter for rule validation_diagnosis: calibrate and rank the candidate effects."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.validation.campaign import CampaignPlan  # noqa: E402
from hdwf.validation.diagnosis import diagnosis_stage  # noqa: E402

# guarded: the re-solves before a further round run in spawned processes, which import this file
if __name__ == "__main__":
    prov = setup(snakemake)  # noqa: F821
    plan = CampaignPlan(**snakemake.params.plan)  # noqa: F821
    result = diagnosis_stage(snakemake.input.measurements, snakemake.input.tables, plan,  # noqa: F821
                             snakemake.output.json, snakemake.output.points, prov,  # noqa: F821
                             jobs=snakemake.threads)  # noqa: F821
    logging.info("verdict: %s", result["verdict"])
