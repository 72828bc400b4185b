"""Adapter for rule correlation: lost_motion.parquet -> correlation.parquet + figure."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.stats import correlation_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
table = correlation_stage(snakemake.input[0], snakemake.output.table, snakemake.output.figure,  # noqa: F821
                          f"{w.study} / {w.unit}: lost motion against each input", prov)
logging.info("\n%s", table.to_string())
