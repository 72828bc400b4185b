"""Shared by the rule scripts: log to the rule's log file, collect provenance, and build a
``snakemake`` object when a script is run by hand (``mock_snakemake``)."""

import logging

from hdwf.common.provenance import provenance


def setup(snakemake):
    """Log to the rule's log file; return the provenance stamped on every artefact."""
    logging.basicConfig(filename=snakemake.log[0], level=logging.INFO, force=True,
                        format="%(asctime)s %(levelname)s %(message)s")
    return provenance(snakemake.config, snakemake.params.repo)


def mock_snakemake(rule: str, **wildcards):
    raise NotImplementedError("mock_snakemake: not yet written")
