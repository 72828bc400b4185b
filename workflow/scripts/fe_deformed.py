"""Adapter for rule fe_deformed: one design with its displacement fields -> picture + fields."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.fe_study import deformed_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
facts = deformed_stage(snakemake.input[0], w.design, w.unit, dict(snakemake.params.settings),  # noqa: F821
                       snakemake.params.steps_per_ramp, snakemake.output.png, snakemake.output.fields, prov)  # noqa: F821
logging.info("%s", facts)
