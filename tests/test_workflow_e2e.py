"""End to end: `snakemake --cores 2 paper` in a fresh copy of the workflow."""

import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from hdwf.io import read_json, read_parquet_meta

from conftest import ROOT

SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))


def _workspace(tmp_path):
    for item in ("Snakefile", "config.yaml", "workflow", "data"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item)
    return tmp_path


@pytest.mark.e2e
def test_paper_target(tmp_path):
    ws = _workspace(tmp_path)
    run = subprocess.run([SNAKEMAKE, "--cores", "2", "paper"], cwd=ws, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    pdf = ws / "results/paper/report.pdf"
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 100_000
    for unit, rho in (("hd42", 0.6758), ("hd120", 0.7027)):
        corr = pd.read_parquet(ws / f"results/paper/{unit}/correlation.parquet").set_index("parameter")
        assert round(corr.loc["rFS", "spearman_rho"], 4) == rho
        sob = pd.read_parquet(ws / f"results/paper/{unit}/sobol.parquet")
        assert set(sob["sampler"]) == {"exact", "lhs", "halton", "sobol"}
        assert sob["n"].max() >= 65536
        assert read_json(ws / f"results/paper/{unit}/surrogate.json")["r2"] >= 0.98
        prov, _ = read_parquet_meta(ws / f"results/paper/{unit}/lost_motion.parquet")
        assert len(prov["config_hash"]) == 64
    again = subprocess.run([SNAKEMAKE, "--cores", "2", "paper", "--dry-run"], cwd=ws, capture_output=True,
                           text=True, timeout=120)
    assert "Nothing to be done" in again.stdout + again.stderr  # a rerun rebuilds nothing


@pytest.mark.e2e
def test_bad_config_stops_before_any_job(tmp_path):
    ws = _workspace(tmp_path)
    cfg = (ws / "config.yaml").read_text().replace("n_designs: 27", "n_designs: twenty-seven")
    (ws / "config.yaml").write_text(cfg)
    run = subprocess.run([SNAKEMAKE, "--cores", "2", "paper"], cwd=ws, capture_output=True, text=True, timeout=120)
    assert run.returncode != 0
    assert "config.yaml" in run.stderr and "field 'doe.n_designs'" in run.stderr and "'twenty-seven'" in run.stderr
    assert not (ws / "results").exists()
