"""Stages of the FE studies (rules in ``workflow/rules/fe.smk``) over a whole study: design table,
aggregation, mesh convergence and the deformed-mesh picture.  One design's mesh and solve (a job
each) are ``hdwf.stages.fe_solve``.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

from hdwf import PARAMETER_COLUMNS
from hdwf.common.io import atomic_path, read_parquet_meta, write_parquet
from hdwf.drive.geometry import nominal_geometry
from hdwf.fe import solve_lost_motion
from hdwf.fe.bodies import Material
from hdwf.fe.solver import TOL_GAP
from hdwf.stages.fe_solve import DesignJob
from hdwf.study.aggregate import write_lost_motion
from hdwf.study.convergence import convergence_table, twist_resolution_arcmin
from hdwf.study.paper import load_fea_designs


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


def aggregate_stage(row_paths, curve_paths, out_lost_motion, out_curves, provenance: dict, meta: dict) -> pd.DataFrame:
    """All designs' rows into ``lost_motion.parquet`` and their curves into ``curves.parquet``."""
    rows = pd.concat([pd.read_parquet(p) for p in row_paths], ignore_index=True)
    curves = pd.concat([pd.read_parquet(p) for p in curve_paths], ignore_index=True)
    write_lost_motion(rows, out_lost_motion, provenance, meta=meta)
    write_parquet(curves.sort_values(["design_id", "step"]).reset_index(drop=True), out_curves,
                  provenance=provenance, meta=meta)
    return rows


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


def deformed_stage(job: DesignJob, out_png, out_npz, provenance: dict) -> dict:
    """Solve one design keeping the displacement fields; picture of the mesh near the major axis."""
    _, changes, geom = job.model()
    design_id, unit = job.design_id, job.unit
    mesh = job.mesh(geom)
    res = solve_lost_motion(geom, mesh, steps_per_ramp=job.steps_per_ramp, keep_fields=True, changes=changes)
    if res.status != "ok":
        raise RuntimeError(f"{design_id}: solve failed ({res.reason}); no picture of a failed state")
    arrays = {f"{state}:{body}": u for state, per_body in res.fields.items() for body, u in per_body.items()}
    arrays["provenance"] = np.array(json.dumps(provenance, sort_keys=True))   # a string: loads without pickle
    with atomic_path(out_npz) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    pitch = 2 * np.pi * geom.r_fs_pitch / geom.z_fs
    from hdwf.report.figures import deformed_figure, stamped   # matplotlib only here: the per-design jobs start faster
    with stamped(provenance):
        deformed_figure(mesh, res.fields, Material(geom.E, geom.nu),
                        f"{unit} {design_id} at +4 % T_N (Φ = {res.lost_motion_arcmin:.3f} arcmin), true scale", out_png,
                        half_width_mm=2.5 * pitch,
                        xlim=(geom.r_fs_bore - 2 * geom.module, geom.r_cs_root + 3 * geom.module))
    return {"design_id": design_id, "lost_motion_arcmin": res.lost_motion_arcmin}
