"""Rule sobol: surrogate.json -> sobol.parquet (exact + convergence runs) + figure."""
import logging

from _helpers import folder_of, mock_snakemake, setup

from hdwf import PARAMETERS
from hdwf.report.document import UNIT_NAMES
from hdwf.study.paper import table3_bounds
from hdwf.stages.stats import sobol_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("sobol", study="paper", unit="hd42")

prov = setup(snakemake)
w = snakemake.wildcards
t3 = table3_bounds(folder_of(snakemake.input.bounds), w.unit)
table = sobol_stage(snakemake.input.surrogate, snakemake.output.table, snakemake.output.figure,
                    snakemake.params.samplers, dict(snakemake.params.settings),
                    f"study '{w.study}', {UNIT_NAMES[w.unit]}: Sobol' indices of the surrogate", prov,
                    other_bounds={"table3": ([t3[p][0] for p in PARAMETERS], [t3[p][1] for p in PARAMETERS])})
logging.info("%d rows", len(table))
