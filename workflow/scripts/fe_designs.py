"""Rule fe_designs: our LHS or the paper's points -> the FE study's designs.parquet."""

from _helpers import folder_of, mock_snakemake, setup

from hdwf.stages.fe import designs_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_designs", study="fe", unit="hd42")

prov = setup(snakemake)
designs_stage(snakemake.params.designs, snakemake.wildcards.unit, snakemake.input[0],
              folder_of(snakemake.input[0]), snakemake.output[0], prov)
