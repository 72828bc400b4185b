"""Shared by the benchmarks: a fresh copy of the workflow in a temporary folder."""

import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def copy_workflow(dest: Path) -> Path:
    """Snakefile, config, rules/scripts and data into ``dest`` (results/ starts empty)."""
    for item in ("Snakefile", "config.yaml", "workflow", "data"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, dest / item)
    return dest
