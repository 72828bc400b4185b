"""Adapter for rule fe_refined_solve: one design at another mesh refinement -> one row."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.fe_study import refined_solve_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
row = refined_solve_stage(snakemake.input[0], w.design, w.unit, dict(snakemake.params.settings),  # noqa: F821
                          snakemake.params.steps_per_ramp, snakemake.output[0], prov)  # noqa: F821
logging.info("%s", row)
