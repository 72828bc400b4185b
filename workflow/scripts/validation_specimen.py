"""Rule validation_specimen: one specimen, every variant of its campaign's table."""
import logging
from collections import Counter

from _helpers import mock_snakemake, setup

from hdwf.stages.validation_specimen import specimen_stage
from hdwf.validation.variants import SolveSetup

if "snakemake" not in globals():  # run outside Snakemake, from the project root
    snakemake = mock_snakemake("validation_specimen", campaign="demo", specimen="hd42-s001")

prov = setup(snakemake)
p = snakemake.params
table = specimen_stage(SolveSetup(p.unit, p.settings, p.steps_per_ramp), p.specimen, p.variants,
                       snakemake.output[0], prov)
logging.info("%d variants, statuses %s", len(set(table["variant"].to_pylist())),
             dict(Counter(table["status"].to_pylist())))
