"""Adapter for rule surrogate: lost_motion.parquet -> surrogate.json (Eq. 11) + figure."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.paper import table3_bounds  # noqa: E402
from hdwf.surrogate import surrogate_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
model = surrogate_stage(snakemake.input.lost_motion, snakemake.output.model, snakemake.output.figure,  # noqa: F821
                        snakemake.params.bounds_source, table3_bounds(snakemake.params.data_dir, w.unit),  # noqa: F821
                        f"{w.study} / {w.unit}: data and quadratic surrogate", prov)
logging.info("R2 %.4f, Q2_LOO %.4f, RMSE %.4g", model.r2, model.q2_loo, model.rmse)
