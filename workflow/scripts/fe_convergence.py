"""Rule fe_convergence: Φ at three refinements -> convergence.parquet with the GCI."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe import convergence_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_convergence", study="fe", unit="hd42")

prov = setup(snakemake)
w = snakemake.wildcards
table = convergence_stage(snakemake.input.default, snakemake.input.other_meshes, snakemake.params.refinement,
                          snakemake.output[0], prov, {"study": w.study, "unit": w.unit})
logging.info("\n%s", table.to_string())
