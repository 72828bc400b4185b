"""Adapter for rule full_report: every study's artefacts -> results/report.pdf (hdwf.report.document)."""
import sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.report.document import full_report  # noqa: E402

from hdwf.drive.geometry import assumptions_table  # noqa: E402

prov = setup(snakemake)  # noqa: F821
full_report(files=dict(snakemake.input.items()), studies={k: dict(v) for k, v in snakemake.params.studies.items()},  # noqa: F821
            data_dir=snakemake.params.data_dir, provenance=prov, out=snakemake.output[0],  # noqa: F821
            assumptions=assumptions_table(), fe_settings=dict(snakemake.params.fe_settings),  # noqa: F821
            campaigns=list(snakemake.params.campaigns))  # noqa: F821
