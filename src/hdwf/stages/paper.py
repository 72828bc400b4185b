"""Stage of ``workflow/rules/paper.smk``: the paper's Table 4/5 as a study's lost-motion table."""

from __future__ import annotations

from pathlib import Path

from hdwf.study.aggregate import write_lost_motion
from hdwf.study.paper import load_fea_designs


def paper_lost_motion_stage(data_dir: str | Path, unit: str, out: str | Path, provenance: dict) -> Path:
    """The paper's Table 4/5 as a study's lost-motion table (its Ansys FEA results)."""
    df = load_fea_designs(data_dir, unit)
    df["status"] = "published"
    return write_lost_motion(df, out, provenance, meta={"source": f"paper {unit} FEA table", "unit": unit})
