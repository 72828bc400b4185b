"""Adapter for rule fe_convergence: Φ at three refinements -> convergence.parquet with the GCI."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.fe_study import convergence_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
table = convergence_stage(snakemake.input.default, snakemake.input.other_meshes, snakemake.params.refinement,  # noqa: F821
                          snakemake.output[0], prov, {"study": w.study, "unit": w.unit})  # noqa: F821
logging.info("\n%s", table.to_string())
