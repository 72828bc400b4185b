"""Adapter for rule sobol: surrogate.json -> sobol.parquet (exact + convergence runs) + figure."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf import PARAMETERS  # noqa: E402
from hdwf.paper import table3_bounds  # noqa: E402
from hdwf.sobol import sobol_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
t3 = table3_bounds(snakemake.params.data_dir, w.unit)  # noqa: F821
table = sobol_stage(snakemake.input[0], snakemake.output.table, snakemake.output.figure,  # noqa: F821
                    snakemake.params.samplers, dict(snakemake.params.settings),  # noqa: F821
                    f"{w.study} / {w.unit}: Sobol' indices of the surrogate", prov,
                    other_bounds={"table3": ([t3[p][0] for p in PARAMETERS], [t3[p][1] for p in PARAMETERS])})
logging.info("%d rows", len(table))
