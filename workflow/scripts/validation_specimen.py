"""Adapter for rule validation_specimen: one specimen, every variant of its campaign's table."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.validation.campaign import specimen_stage  # noqa: E402

prov = setup(snakemake)  # noqa: F821
p = snakemake.params  # noqa: F821
table = specimen_stage(p.unit, p.specimen, p.settings, p.steps_per_ramp, p.variants, snakemake.output[0], prov)  # noqa: F821
logging.info("%d variants, statuses %s", table["variant"].nunique(), table["status"].value_counts().to_dict())
