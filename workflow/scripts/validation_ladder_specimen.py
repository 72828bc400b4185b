"""Adapter for rule validation_ladder_specimen: solve the ladder's model variants at one specimen."""
import json, logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.campaign import specimen_stage  # noqa: E402
from hdwf.diagnosis import ladder_variants  # noqa: E402

prov = setup(snakemake)  # noqa: F821
p = snakemake.params  # noqa: F821
diag = json.loads(open(snakemake.input.diagnosis).read())  # noqa: F821
variants = [eff for _, eff in ladder_variants(diag)]
table = specimen_stage(p.unit, p.specimen, p.settings, p.steps_per_ramp, variants, snakemake.output[0], prov,  # noqa: F821
                       reuse=snakemake.input.table)  # noqa: F821
logging.info("%d ladder variants", table["variant"].nunique())
