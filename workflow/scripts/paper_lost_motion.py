"""Rule paper_lost_motion: the paper's Table 4/5 -> lost_motion.parquet."""
import logging

from _helpers import folder_of, mock_snakemake, setup

from hdwf.stages.paper import paper_lost_motion_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("paper_lost_motion", study="paper", unit="hd42")

prov = setup(snakemake)
paper_lost_motion_stage(folder_of(snakemake.input.table), snakemake.wildcards.unit, snakemake.output[0], prov)
logging.info("wrote %s", snakemake.output[0])
