"""The per-specimen stage of a validation campaign (rule ``validation_specimen`` in
``workflow/rules/validation.smk``): mesh one specimen once and solve every variant of its table.

A campaign runs one such job per specimen, each a fresh Python process; it writes an Arrow table
and never imports pandas, which would add a quarter of a second to each one's start.
"""

from __future__ import annotations

import pyarrow as pa

from hdwf.common.io import write_parquet
from hdwf.validation.variants import SolveSetup, solve_specimen


def specimen_stage(setup: SolveSetup, specimen: dict, variants: list[dict], out, provenance: dict) -> pa.Table:
    """Mesh one specimen once and solve it for every variant: its campaign table.

    Parameters
    ----------
    setup : SolveSetup
        Drive, mesh settings and load steps.
    specimen : dict
        ``specimen_id`` and the parameter columns (``specimen_record``).
    variants : list of dict
        The campaign's variants (``CampaignPlan.table_variants``).
    out : path
        The table (Parquet).
    provenance : dict
        Stamped on the table.

    Returns
    -------
    pyarrow.Table
        The table written.
    """
    table = solve_specimen(setup, specimen, variants)
    write_parquet(table, out, provenance=provenance,
                  meta={"unit": setup.unit, "specimen_id": specimen["specimen_id"], "mesh": setup.mesh})
    return table
