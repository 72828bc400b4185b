"""Adapter for rule fe_designs: our LHS or the paper's points -> the FE study's designs.parquet."""
import sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.fe_study import designs_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
designs_stage(snakemake.params.designs, snakemake.wildcards.unit, snakemake.input[0],  # noqa: F821
              snakemake.params.data_dir, snakemake.output[0], prov)  # noqa: F821
