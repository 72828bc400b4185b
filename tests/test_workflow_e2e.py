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


@pytest.mark.e2e
def test_fe_study_chain_on_a_coarse_mesh(tmp_path):
    """Per-design mesh -> solve jobs, benchmark files and the aggregated tables of an FE study
    (22 designs, the fewest the quadratic surrogate accepts, on a coarse mesh)."""
    import yaml

    ws = _workspace(tmp_path)
    config = yaml.safe_load((ws / "config.yaml").read_text())
    config["doe"]["n_designs"] = 22
    config["fe"].update(elements_over_height=4, elements_over_thickness=3, steps_per_ramp=1)
    for study in config["studies"].values():
        study["units"] = ["hd42"]
    (ws / "config.yaml").write_text(yaml.safe_dump(config))
    targets = ["results/fe/hd42/lost_motion.parquet", "results/fe/hd42/curves.parquet",
               "results/fe/hd42/correlation.parquet"]
    run = subprocess.run([SNAKEMAKE, "--cores", "2", *targets], cwd=ws, capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stderr[-3000:]
    lm = pd.read_parquet(ws / targets[0])
    assert len(lm) == 22 and (lm["status"] == "ok").all()
    assert list(lm.columns[:10]) == ["design_id", "d_mm", "D_mm", "Gr_mm", "rFS_mm", "rCS_mm", "phi_plus_arcmin",
                                     "phi_minus_arcmin", "lost_motion_arcmin", "status"]
    # Φ = φ + φ′ by definition, and the solve costs more than one factorisation of the same matrix.
    assert (lm["lost_motion_arcmin"] - lm["phi_plus_arcmin"] - lm["phi_minus_arcmin"]).abs().max() < 1e-9
    assert (lm["solve_s"] > lm["factorize_s"]).all()
    curves = pd.read_parquet(ws / targets[1])
    assert list(curves.columns) == ["design_id", "step", "torque_Nm", "twist_arcmin"]
    assert len(curves) == 22 * 5  # 0 -> +T -> 0 -> -T -> 0 with one step per ramp
    assert curves["torque_Nm"].abs().max() == pytest.approx(0.96)
    assert (ws / "results/fe/hd42/mesh/hd42-lhs-01.msh").stat().st_size > 0
    bench = (ws / "results/fe/hd42/benchmarks/solve_hd42-lhs-01.tsv").read_text().splitlines()
    assert bench[0].startswith("s\t") and len(bench) == 2
