"""Adapter for rule validation_ladder: RMSE, bias and ΔBIC of every model variant of the ladder."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.diagnosis import ladder_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
ladder = ladder_stage(snakemake.input.measurements, snakemake.input.diagnosis, snakemake.input.tables,  # noqa: F821
                      snakemake.output[0], prov)  # noqa: F821
logging.info("\n%s", ladder.to_string())
