"""Adapter for rule fe_solve: one design's mesh -> its lost-motion row and torque–twist curve."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.fe_study import solve_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
row = solve_stage(snakemake.input.designs, w.design, w.unit, snakemake.input.mesh,  # noqa: F821
                  snakemake.params.steps_per_ramp, snakemake.output.row, snakemake.output.curve, prov)  # noqa: F821
logging.info("%s", row)
