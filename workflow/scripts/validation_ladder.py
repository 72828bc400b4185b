"""Adapter for rule validation_ladder: the ladder's variants solved where the tables lack them,
then RMSE, bias and ΔBIC of every rung."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.validation.diagnosis import ladder_stage  # noqa: E402

# guarded: the solves run in spawned processes, which import this file
if __name__ == "__main__":
    prov = setup(snakemake)  # noqa: F821
    p = snakemake.params  # noqa: F821
    ladder = ladder_stage(snakemake.input.measurements, snakemake.input.diagnosis,  # noqa: F821
                          snakemake.input.tables, snakemake.output[0], prov, p.unit,  # noqa: F821
                          dict(p.settings), p.steps_per_ramp, jobs=snakemake.threads)  # noqa: F821
    logging.info("\n%s", ladder.to_string())
