"""The FE study stages with switched-on effects (``fe.effects``): the mesh and the solve carry them."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from hdwf.drive.design import MeshSettings, geometry_of
from hdwf.fe import solve_lost_motion
from hdwf.stages.fe_solve import DesignOutputs, refined_solve_stage, solve_stage
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
    row = solve_stage(designs, "d1", "hd42", MESH, 1, out, {}, effects=EFFECTS)
    assert row["status"] == "ok", row["status"]
    assert out.msh.stat().st_size > 0 and out.curve.exists()

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

    refined = refined_solve_stage(designs, "d1", "hd42", MESH, 1, tmp_path / "refined.parquet", {},
                                  effects=EFFECTS)
    assert refined["lost_motion_arcmin"] == pytest.approx(row["lost_motion_arcmin"], abs=1e-9)
