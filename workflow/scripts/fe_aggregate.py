"""Rule fe_aggregate: per-design rows and curves -> lost_motion.parquet, curves.parquet."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe import aggregate_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_aggregate", study="fe", unit="hd42")

prov = setup(snakemake)
w = snakemake.wildcards
rows = aggregate_stage(snakemake.input.rows, snakemake.input.curves, snakemake.output.lost_motion,
                       snakemake.output.curves, prov, {"study": w.study, "unit": w.unit, "source": "hdwf FE",
                                         "effects": dict(snakemake.params.effects),
                                         "calibrated_on": snakemake.params.calibrated_on})
logging.info("%d designs, %d ok", len(rows), int((rows["status"] == "ok").sum()))
