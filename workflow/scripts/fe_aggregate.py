"""Adapter for rule fe_aggregate: per-design rows and curves -> lost_motion.parquet, curves.parquet."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.fe_study import aggregate_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
rows = aggregate_stage(snakemake.input.rows, snakemake.input.curves, snakemake.output.lost_motion,  # noqa: F821
                       snakemake.output.curves, prov, {"study": w.study, "unit": w.unit, "source": "hdwf FE"})  # noqa: F821
logging.info("%d designs, %d ok", len(rows), int((rows["status"] == "ok").sum()))
