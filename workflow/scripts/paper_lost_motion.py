"""Adapter for rule paper_lost_motion: the paper's Table 4/5 -> lost_motion.parquet."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.aggregate import paper_lost_motion_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
paper_lost_motion_stage(snakemake.params.data_dir, snakemake.wildcards.unit, snakemake.output[0], prov)  # noqa: F821
logging.info("wrote %s", snakemake.output[0])  # noqa: F821
