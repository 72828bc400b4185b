"""Shared by the adapters: log to the rule's log file and collect provenance."""

import logging

from hdwf.provenance import provenance


def setup(snakemake):
    logging.basicConfig(filename=snakemake.log[0], level=logging.INFO, force=True,
                        format="%(asctime)s %(levelname)s %(message)s")
    return provenance(snakemake.config, snakemake.params.repo)
