"""Adapter for rule study_report: the study's artefacts -> report.pdf (hdwf.report.document)."""
import sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.report.document import study_report  # noqa: E402

prov = setup(snakemake)  # noqa: F821
study_report(study=snakemake.wildcards.study, units=snakemake.params.units,  # noqa: F821
             files=dict(snakemake.input.items()), data_dir=snakemake.params.data_dir,  # noqa: F821
             study_config=dict(snakemake.params.study_config), provenance=prov,  # noqa: F821
             out=snakemake.output[0])  # noqa: F821
