"""Rule fe_deformed: one design with its displacement fields -> picture + fields."""
import logging

from _helpers import mock_snakemake, setup

from hdwf.stages.fe import deformed_stage
from hdwf.stages.fe_solve import DesignJob

if "snakemake" not in globals():  # run by hand, e.g. to debug one step (see _helpers.mock_snakemake)
    snakemake = mock_snakemake("fe_deformed", study="fe", unit="hd42", design="hd42-lhs-01")

prov = setup(snakemake)
w, p = snakemake.wildcards, snakemake.params
job = DesignJob(snakemake.input[0], w.design, w.unit, dict(p.settings), p.steps_per_ramp, dict(p.effects))
facts = deformed_stage(job, snakemake.output.png, snakemake.output.fields, prov)
logging.info("%s", facts)
