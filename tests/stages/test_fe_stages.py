"""The FE study stages with switched-on effects (``fe.effects``): the mesh and the solve carry them."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hdwf.common.io import arrow_row, arrow_table, write_parquet
from hdwf.drive.design import MeshSettings, geometry_of
from hdwf.fe import solve_lost_motion
from hdwf.stages.fe import aggregate_stage
from hdwf.stages.fe_solve import DesignJob, DesignOutputs, refined_solve_stage, solve_stage
from hdwf.validation.effects import model_changes

# HD 42, Table 3's nominal bearing, r_FS = r_CS = 5 µm
DESIGN = {"design_id": "d1", "d_mm": 31.0, "D_mm": 42.0, "Gr_mm": 0.015, "rFS_mm": 0.005, "rCS_mm": 0.005}
MESH = {"elements_over_height": 5, "elements_over_thickness": 3, "refinement": 1.0, "symmetry": "half"}
K_CUP = 6.0e4  # N·m/rad
EFFECTS = {"preload": {"interference_m": 0.1}, "fs_cup_torsion": {"K_Nm_per_rad": K_CUP}}


@pytest.mark.slow
def test_study_stages_solve_the_switched_on_effects(tmp_path):
    """The mesh stage thickens the teeth, the solve stage adds the cup in series: Φ is the preloaded
    section's own Φ plus 2 T / K (a spring in series twists T / K at +T and at −T), and the
    mesh-convergence stage at the study's refinement gives the same Φ."""
    designs = tmp_path / "designs.parquet"
    pd.DataFrame([DESIGN]).to_parquet(designs)
    out = DesignOutputs(tmp_path / "d1.msh", tmp_path / "row.parquet", tmp_path / "curve.parquet")
    row = solve_stage(DesignJob(designs, "d1", "hd42", MESH, 1, EFFECTS), out, {})
    assert row["status"] == "ok", row["status"]
    assert out.msh.stat().st_size > 0 and out.curve.exists()
    # the teeth re-paired from scratch at ±T: in the row, within the 0.05 µm the rows were settled to
    assert 0.0 <= row["max_penetration_redetected_um"] <= 0.05

    preload_only = model_changes({"preload": EFFECTS["preload"]})
    g = geometry_of("hd42", DESIGN, **preload_only.geometry_part())
    alone = solve_lost_motion(g, MeshSettings.from_mapping(MESH).mesh(g), 1, changes=preload_only)
    series_arcmin = 2 * (g.torque / 1000.0) / K_CUP * 180 / math.pi * 60  # g.torque in N·mm
    assert row["lost_motion_arcmin"] - alone.lost_motion_arcmin == pytest.approx(series_arcmin, rel=1e-9)
    # the curve of the test 0 -> +T -> 0 -> -T -> 0 (one step a ramp) ends where the row does:
    # its twist from the start to +T is φ, to -T minus φ' (the cup's twist included)
    curve = pd.read_parquet(out.curve).sort_values("step")
    T = g.torque / 1000.0
    assert curve["torque_Nm"].to_numpy() == pytest.approx([0.0, T, 0.0, -T, 0.0], abs=1e-3 * T)
    twist = curve["twist_arcmin"].to_numpy()
    assert twist[0] == 0.0
    assert twist[1] == pytest.approx(row["phi_plus_arcmin"], rel=1e-12)
    assert -twist[3] == pytest.approx(row["phi_minus_arcmin"], rel=1e-12)
    assert twist[1] - twist[3] == pytest.approx(row["lost_motion_arcmin"], rel=1e-12)
    # 0.1 m = 18 µm exceeds the 10 µm of rigid clearance per flank: no play left, Φ is elastic only
    assert alone.lost_motion_arcmin < 0.34  # a tenth of the bare section's 3.4 arcmin

    refined = refined_solve_stage(DesignJob(designs, "d1", "hd42", MESH, 1, EFFECTS), tmp_path / "refined.parquet", {})
    assert refined["lost_motion_arcmin"] == pytest.approx(row["lost_motion_arcmin"], abs=1e-9)


def test_a_failed_designs_row_aggregates_without_a_number(tmp_path):
    """Rows and curves as the solve jobs write them (Arrow, no pandas), one design failed: the study's
    table keeps every Φ column a float, the failed design's Φ missing (never a number), its status
    saying why."""
    nan = float("nan")
    rows, curves = [], []
    for design_id, phi, status in (("d1", 0.5, "ok"), ("d2", nan, "failed: contact did not converge")):
        row = {**DESIGN, "design_id": design_id, "phi_plus_arcmin": phi / 2 if phi == phi else nan,
               "phi_minus_arcmin": phi / 2 if phi == phi else nan, "lost_motion_arcmin": phi, "status": status,
               "iterations": 200}
        rows.append(write_parquet(arrow_row(row), tmp_path / f"{design_id}.parquet", provenance={}))
        curve = {"design_id": [design_id] * 2, "step": np.arange(2), "torque_Nm": np.array([0.0, 1.0]),
                 "twist_arcmin": np.array([0.0, phi])}
        curves.append(write_parquet(arrow_table(curve), tmp_path / f"{design_id}_curve.parquet", provenance={}))
    aggregate_stage(rows, curves, tmp_path / "lost_motion.parquet", tmp_path / "curves.parquet", {}, {"unit": "hd42"})
    table = pd.read_parquet(tmp_path / "lost_motion.parquet").set_index("design_id")
    assert all(table[c].dtype == np.float64 for c in ("phi_plus_arcmin", "phi_minus_arcmin", "lost_motion_arcmin"))
    assert table.loc["d1", "lost_motion_arcmin"] == 0.5 and np.isnan(table.loc["d2", "lost_motion_arcmin"])
    assert table.loc["d2", "status"].startswith("failed")
    assert pd.read_parquet(tmp_path / "curves.parquet")["twist_arcmin"].dtype == np.float64


def test_a_mesh_that_fails_leaves_no_file_behind(tmp_path, monkeypatch):
    """gmsh writes the mesh under a temporary ``.msh`` name (it picks the format from the extension);
    a mesh that fails after gmsh wrote must leave neither that file nor the ``.tmp`` beside the
    results, and no mesh, row or curve."""
    designs = tmp_path / "designs.parquet"
    pd.DataFrame([DESIGN]).to_parquet(designs)

    def fails_after_writing(self, geom, path=None):
        with open(path, "w") as f:
            f.write("$MeshFormat")
        raise RuntimeError("gmsh: no mesh")

    monkeypatch.setattr(MeshSettings, "mesh", fails_after_writing)
    out = DesignOutputs(tmp_path / "mesh" / "d1.msh", tmp_path / "row.parquet", tmp_path / "curve.parquet")
    with pytest.raises(RuntimeError, match="no mesh"):
        solve_stage(DesignJob(designs, "d1", "hd42", MESH, 1), out, {})
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == ["designs.parquet"]
