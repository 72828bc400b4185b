"""Rule surrogate: lost_motion.parquet -> surrogate.json (Eq. 11) + figure."""
import logging

from _helpers import folder_of, mock_snakemake, setup

from hdwf.report.document import UNIT_NAMES
from hdwf.study.paper import table3_bounds
from hdwf.stages.stats import surrogate_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("surrogate", study="paper", unit="hd42")

prov = setup(snakemake)
w = snakemake.wildcards
model = surrogate_stage(snakemake.input.lost_motion, snakemake.output.model, snakemake.output.figure,
                        snakemake.params.bounds_source, table3_bounds(folder_of(snakemake.input.bounds), w.unit),
                        f"study '{w.study}', {UNIT_NAMES[w.unit]}: data and quadratic surrogate", prov)
logging.info("R2 %.4f, Q2_LOO %.4f, RMSE %.4g", model.r2, model.q2_loo, model.rmse)
