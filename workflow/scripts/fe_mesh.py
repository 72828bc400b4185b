"""Rule fe_mesh: one design -> gmsh .msh (review) and .npz (solver input)."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe import mesh_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_mesh", study="fe", unit="hd42", design="hd42-lhs-01")

setup(snakemake)
w = snakemake.wildcards
facts = mesh_stage(snakemake.input[0], w.design, w.unit, dict(snakemake.params.settings),
                   snakemake.output.msh, snakemake.output.npz,
                   effects=dict(snakemake.params.effects))
logging.info("%s", facts)
