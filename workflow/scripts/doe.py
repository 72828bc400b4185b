"""Adapter for rule doe: Table 3 bounds -> optimal LHS (hdwf.doe.doe_stage)."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.doe import doe_stage  # noqa: E402
from hdwf.paper import table3_bounds  # noqa: E402

prov = setup(snakemake)  # noqa: F821
unit = snakemake.wildcards.unit  # noqa: F821
bounds = table3_bounds(snakemake.config["paper_data"], unit)  # noqa: F821
df = doe_stage(bounds, snakemake.params.n, snakemake.params.seed, snakemake.params.optimization,  # noqa: F821
               snakemake.output[0], prov, unit)  # noqa: F821
logging.info("wrote %d designs for %s", len(df), unit)
