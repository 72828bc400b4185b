"""Rule fe_deformed: one design with its displacement fields -> picture + fields."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe import deformed_stage

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_deformed", study="fe", unit="hd42", design="hd42-lhs-01")

prov = setup(snakemake)
w = snakemake.wildcards
facts = deformed_stage(snakemake.input[0], w.design, w.unit, dict(snakemake.params.settings),
                       snakemake.params.steps_per_ramp, snakemake.output.png, snakemake.output.fields, prov,
                       effects=dict(snakemake.params.effects))
logging.info("%s", facts)
