"""Stages of the FE studies (rules in ``workflow/rules/fe.smk``): design table, per-design mesh
and solve, aggregation, mesh convergence and the deformed-mesh picture.

A design is meshed and solved in one job; its gmsh ``.msh`` is kept for review.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np
import pandas as pd

from hdwf import PARAMETER_COLUMNS
from hdwf.common.io import atomic_path, read_parquet_meta, write_parquet
from hdwf.drive.design import MeshSettings, design_parameters, geometry_of
from hdwf.drive.mesh import DriveMesh
from hdwf.drive.geometry import nominal_geometry
from hdwf.fe import solve_lost_motion
from hdwf.fe.solver import TOL_GAP
from hdwf.study.aggregate import write_lost_motion
from hdwf.study.convergence import convergence_table, twist_resolution_arcmin
from hdwf.study.fe_design import solve_design
from hdwf.study.paper import load_fea_designs
from hdwf.validation.effects import model_changes


def designs_stage(source: str, unit: str, source_path, data_dir, out, provenance: dict) -> pd.DataFrame:
    """The design table an FE study solves: our optimal LHS (``doe``) or the paper's points (``paper``)."""
    if source == "paper":
        df = load_fea_designs(data_dir, unit)[["design_id", *PARAMETER_COLUMNS]]
        meta = {"source": "paper Table 4/5 design points", "unit": unit}
    else:
        df = pd.read_parquet(source_path)
        meta = {"source": "hdwf optimal LHS", "unit": unit, **(read_parquet_meta(source_path)[1] or {})}
    write_parquet(df, out, provenance=provenance, meta=meta)
    return df


def _design_model(designs_path, design_id: str, unit: str, effects: Mapping | None):
    """One design's parameters, the study's switched-on changes (``fe.effects``) and the geometry
    they shape (the preload thickens the teeth)."""
    params = design_parameters(designs_path, design_id)
    changes = model_changes(effects)
    return params, changes, geometry_of(unit, params, **changes.geometry_part())


def _mesh_to(geom, settings: Mapping, out_msh) -> DriveMesh:
    """Mesh a design's geometry, writing gmsh's ``.msh`` for review; returns the mesh."""
    with atomic_path(out_msh) as tmp_msh:
        # gmsh picks the format from the extension, so the temporary name keeps ".msh".
        tmp_named = tmp_msh.with_suffix(".msh")
        mesh = MeshSettings.from_mapping(settings).mesh(geom, path=str(tmp_named))
        tmp_named.replace(tmp_msh)
    return mesh


@dataclass(frozen=True)
class DesignOutputs:
    """Where one design's solve writes: its mesh (``.msh``), its row and its torque–twist curve."""
    msh: str | Path
    row: str | Path
    curve: str | Path


def solve_stage(designs_path, design_id: str, unit: str, settings: Mapping, steps_per_ramp: int,
                out: DesignOutputs, provenance: dict, effects: Mapping | None = None) -> dict:
    """Mesh one design and solve it into its row and torque–twist curve (Parquet each), with the
    study's switched-on ``effects`` (``{name: {parameter: value}}``).  One job does both: the mesh
    takes a second or two, less than a job of its own spends starting and passing it on."""
    params, changes, geom = _design_model(designs_path, design_id, unit, effects)   # the preload reshapes the outline
    t0 = time.perf_counter()
    mesh = _mesh_to(geom, settings, out.msh)
    mesh_s = time.perf_counter() - t0
    row, curve = solve_design(unit, params, mesh, steps_per_ramp, design_id, changes=changes)
    row["mesh_s"] = mesh_s
    write_parquet(pd.DataFrame([row]), out.row, provenance=provenance, meta={"unit": unit})
    write_parquet(curve, out.curve, provenance=provenance, meta={"unit": unit})
    return row


def aggregate_stage(row_paths, curve_paths, out_lost_motion, out_curves, provenance: dict, meta: dict) -> pd.DataFrame:
    """All designs' rows into ``lost_motion.parquet`` and their curves into ``curves.parquet``."""
    rows = pd.concat([pd.read_parquet(p) for p in row_paths], ignore_index=True)
    curves = pd.concat([pd.read_parquet(p) for p in curve_paths], ignore_index=True)
    write_lost_motion(rows, out_lost_motion, provenance, meta=meta)
    write_parquet(curves.sort_values(["design_id", "step"]).reset_index(drop=True), out_curves,
                  provenance=provenance, meta=meta)
    return rows


def refined_solve_stage(designs_path, design_id: str, unit: str, settings: Mapping, steps_per_ramp: int, out,
                        provenance: dict, effects: Mapping | None = None) -> dict:
    """Mesh and solve one design at another refinement (mesh-convergence runs); one row out."""
    params, changes, geom = _design_model(designs_path, design_id, unit, effects)
    row, _ = solve_design(unit, params, MeshSettings.from_mapping(settings).mesh(geom), steps_per_ramp, design_id,
                          changes=changes)
    row["refinement"] = float(settings["refinement"])
    write_parquet(pd.DataFrame([row]), out, provenance=provenance, meta={"unit": unit})
    return row


def convergence_stage(default_lost_motion, other_rows, default_refinement: float, out, provenance: dict,
                      meta: dict) -> pd.DataFrame:
    """Φ of every design on each mesh, the relative change and the GCI (``convergence.parquet``)."""
    default = pd.read_parquet(default_lost_motion).assign(refinement=float(default_refinement))
    others = pd.concat([pd.read_parquet(p) for p in other_rows], ignore_index=True)
    cols = ["design_id", "refinement", "h_tooth_mm", "lost_motion_arcmin"]
    results = pd.concat([default[cols], others[cols]], ignore_index=True).rename(columns={"h_tooth_mm": "h_mm"})
    resolution = twist_resolution_arcmin(TOL_GAP, nominal_geometry(meta["unit"]).r_cs_base)
    table = convergence_table(results, resolution)
    write_parquet(table, out, provenance=provenance, meta={**meta, "criterion": "two finest meshes differ < 2 %"})
    return table


def deformed_stage(designs_path, design_id: str, unit: str, settings: Mapping, steps_per_ramp: int, out_png,
                   out_npz, provenance: dict, effects: Mapping | None = None) -> dict:
    """Solve one design keeping the displacement fields; picture of the mesh near the major axis."""
    _, changes, geom = _design_model(designs_path, design_id, unit, effects)
    mesh = MeshSettings.from_mapping(settings).mesh(geom)
    res = solve_lost_motion(geom, mesh, steps_per_ramp=steps_per_ramp, keep_fields=True, changes=changes)
    if res.status != "ok":
        raise RuntimeError(f"{design_id}: solve failed ({res.reason}); no picture of a failed state")
    arrays = {f"{state}:{body}": u for state, per_body in res.fields.items() for body, u in per_body.items()}
    with atomic_path(out_npz) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    pitch = 2 * np.pi * geom.r_fs_pitch / geom.z_fs
    from hdwf.report.figures import deformed_figure   # matplotlib only here: the per-design jobs start faster
    deformed_figure(mesh, res.fields, f"{unit} {design_id} at +4 % T_N (Φ = {res.lost_motion_arcmin:.3f} arcmin), "
                    "true scale", out_png, half_width_mm=2.5 * pitch,
                    xlim=(geom.r_fs_bore - 2 * geom.module, geom.r_cs_root + 3 * geom.module))
    return {"design_id": design_id, "lost_motion_arcmin": res.lost_motion_arcmin}
