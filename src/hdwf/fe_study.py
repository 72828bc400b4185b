"""The FE study stages: per-design mesh and solve, aggregation and mesh convergence.

Glue between the design tables, ``hdwf.geometry``/``hdwf.mesh``/``hdwf.fe`` and the
artefacts. A design's mesh is stored twice: as gmsh ``.msh`` for review (written by gmsh
itself) and as ``.npz`` (nodes, triangles, named node and edge sets of each body) that the
solve stage reads back, so a solve never re-meshes.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pandas as pd

from . import PARAMETER_COLUMNS
from .aggregate import write_lost_motion
from .convergence import gci
from .io import atomic_path, write_parquet

CURVE_COLUMNS = ["design_id", "step", "torque_Nm", "twist_arcmin"]


def design_parameters(designs_path, design_id: str) -> dict[str, float]:
    df = pd.read_parquet(designs_path)
    row = df[df["design_id"] == design_id]
    if len(row) != 1:
        raise KeyError(f"{designs_path}: design '{design_id}' not found (have {len(df)} designs)")
    return {c: float(row.iloc[0][c]) for c in PARAMETER_COLUMNS}


def geometry_of(unit: str, params: dict[str, float]):
    from .geometry import drive_geometry

    return drive_geometry(unit, params["d_mm"], params["D_mm"], params["Gr_mm"], params["rFS_mm"], params["rCS_mm"])


# ------------------------------------------------------------------ mesh storage

def _mesh(geom, settings: dict, path=None):
    """Mesh with the study's settings; ``symmetry`` is passed only when it is not the full model."""
    from .mesh import build_mesh

    extra = {} if settings.get("symmetry", "full") == "full" else {"symmetry": settings["symmetry"]}
    return build_mesh(geom, settings["elements_over_height"], settings["elements_over_thickness"],
                      settings.get("refinement", 1.0), path=path, **extra)


def save_drive_mesh(mesh, path) -> Path:
    arrays = {"__sizes__": np.array(json.dumps(mesh.sizes))}
    for name, body in mesh.bodies.items():
        arrays[f"{name}:p"] = body.mesh.p
        arrays[f"{name}:t"] = body.mesh.t
        arrays[f"{name}:thickness"] = np.array(body.thickness)
        for k, v in body.node_sets.items():
            arrays[f"{name}:node:{k}"] = np.asarray(v)
        for k, v in body.edge_sets.items():
            arrays[f"{name}:edge:{k}"] = np.asarray(v)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    return Path(path)


def load_drive_mesh(path):
    from skfem import MeshTri

    from .mesh import BodyMesh, DriveMesh

    data = np.load(path)
    bodies: dict[str, dict] = {}
    for key in data.files:
        if key == "__sizes__":
            continue
        name, kind, *rest = key.split(":")
        b = bodies.setdefault(name, {"node_sets": {}, "edge_sets": {}})
        if kind in ("p", "t", "thickness"):
            b[kind] = data[key]
        elif kind == "node":
            b["node_sets"][rest[0]] = data[key]
        elif kind == "edge":
            b["edge_sets"][rest[0]] = data[key]
    out = {name: BodyMesh(name=name, mesh=MeshTri(b["p"], b["t"]), thickness=float(b["thickness"]),
                          node_sets=b["node_sets"], edge_sets=b["edge_sets"]) for name, b in bodies.items()}
    return DriveMesh(bodies=out, sizes=json.loads(str(data["__sizes__"])))


def mesh_stage(designs_path, design_id: str, unit: str, settings: dict, out_msh, out_npz) -> dict:
    """Mesh one design: gmsh ``.msh`` for review, ``.npz`` for the solver; returns mesh facts."""
    geom = geometry_of(unit, design_parameters(designs_path, design_id))
    t0 = time.perf_counter()
    with atomic_path(out_msh) as tmp_msh:
        # gmsh picks the format from the extension, so the temporary name keeps ".msh".
        tmp_named = tmp_msh.with_suffix(".msh")
        mesh = _mesh(geom, settings, path=str(tmp_named))
        tmp_named.replace(tmp_msh)
    save_drive_mesh(mesh, out_npz)
    return {"design_id": design_id, "n_nodes": mesh.n_nodes, "mesh_s": time.perf_counter() - t0}


# ------------------------------------------------------------------ solve

def solve_design(unit: str, params: dict[str, float], mesh, steps_per_ramp: int, design_id: str,
                 **solver_options) -> tuple[dict, pd.DataFrame]:
    """Solve one design; return its lost-motion row and its torque–twist curve.

    A failed solve gives status ``failed: <reason>`` and no Φ (never a silent number).
    """
    from .fe import solve_lost_motion

    geom = geometry_of(unit, params)
    res = solve_lost_motion(geom, mesh, steps_per_ramp=steps_per_ramp, **solver_options)
    ok = res.status == "ok"
    row = {"design_id": design_id, **params,
           "phi_plus_arcmin": res.phi_plus_arcmin if ok else np.nan,
           "phi_minus_arcmin": res.phi_minus_arcmin if ok else np.nan,
           "lost_motion_arcmin": res.lost_motion_arcmin if ok else np.nan,
           "status": "ok" if ok else f"failed: {res.reason}",
           "teeth_in_contact": int(res.teeth_in_contact), "max_penetration_um": float(res.max_penetration_um),
           "iterations": int(res.iterations), "n_dofs": int(res.n_dofs), "solve_s": float(res.solve_s),
           "factorize_s": float(res.factorize_s), "h_tooth_mm": float(mesh.sizes.get("tooth", np.nan))}
    curve = pd.DataFrame({"design_id": design_id, "step": np.asarray(res.step, dtype="int64"),
                          "torque_Nm": np.asarray(res.torque_Nm, float),
                          "twist_arcmin": np.asarray(res.twist_arcmin, float)}, columns=CURVE_COLUMNS)
    return row, curve


def solve_stage(designs_path, design_id: str, unit: str, mesh_npz, steps_per_ramp: int, out_row, out_curve,
                provenance: dict) -> dict:
    params = design_parameters(designs_path, design_id)
    row, curve = solve_design(unit, params, load_drive_mesh(mesh_npz), steps_per_ramp, design_id)
    write_parquet(pd.DataFrame([row]), out_row, provenance=provenance, meta={"unit": unit})
    write_parquet(curve, out_curve, provenance=provenance, meta={"unit": unit})
    return row


def aggregate_stage(row_paths, curve_paths, out_lost_motion, out_curves, provenance: dict, meta: dict) -> pd.DataFrame:
    rows = pd.concat([pd.read_parquet(p) for p in row_paths], ignore_index=True)
    curves = pd.concat([pd.read_parquet(p) for p in curve_paths], ignore_index=True)
    write_lost_motion(rows, out_lost_motion, provenance, meta=meta)
    write_parquet(curves.sort_values(["design_id", "step"]).reset_index(drop=True), out_curves,
                  provenance=provenance, meta=meta)
    return rows


def designs_stage(source: str, unit: str, source_path, data_dir, out, provenance: dict) -> pd.DataFrame:
    """The design table an FE study solves: our optimal LHS (``doe``) or the paper's points (``paper``)."""
    from .io import read_parquet_meta
    from .paper import load_fea_designs

    if source == "paper":
        df = load_fea_designs(data_dir, unit)[["design_id", *PARAMETER_COLUMNS]]
        meta = {"source": "paper Table 4/5 design points", "unit": unit}
    else:
        df = pd.read_parquet(source_path)
        meta = {"source": "hdwf optimal LHS", "unit": unit, **(read_parquet_meta(source_path)[1] or {})}
    write_parquet(df, out, provenance=provenance, meta=meta)
    return df


def refined_solve_stage(designs_path, design_id: str, unit: str, settings: dict, steps_per_ramp: int, out,
                        provenance: dict) -> dict:
    """Mesh and solve one design at another refinement (mesh-convergence runs); one row out."""
    params = design_parameters(designs_path, design_id)
    mesh = _mesh(geometry_of(unit, params), settings)
    row, _ = solve_design(unit, params, mesh, steps_per_ramp, design_id)
    row["refinement"] = float(settings["refinement"])
    write_parquet(pd.DataFrame([row]), out, provenance=provenance, meta={"unit": unit})
    return row


# ------------------------------------------------------------------ mesh convergence

def convergence_table(results: pd.DataFrame) -> pd.DataFrame:
    """One row per design: Φ on the fine, medium and coarse mesh, the GCI and the fine change.

    ``results`` has columns design_id, refinement, h_mm (representative element size),
    lost_motion_arcmin.
    """
    out = []
    levels = ("fine", "medium", "coarse")
    for design_id, sub in results.groupby("design_id", sort=True):
        sub = sub.sort_values("h_mm")  # fine first
        row = {"design_id": design_id}
        for k, r in zip(levels, sub.itertuples()):
            row.update({f"refinement_{k}": float(r.refinement), f"h_{k}_mm": float(r.h_mm),
                        f"phi_{k}_arcmin": float(r.lost_motion_arcmin)})
        phi = sub["lost_motion_arcmin"].to_numpy(float)
        if len(sub) < 2 or not np.isfinite(phi).all():
            row.update({"converged": False, "note": "a refinement failed or is missing"})
        else:
            row["rel_change_fine"] = float(abs(phi[1] - phi[0]) / abs(phi[0]))
            row["converged"] = bool(row["rel_change_fine"] < 0.02)
            row["note"] = ""
            if len(sub) == 3:
                g = gci(tuple(sub["h_mm"]), tuple(phi))
                row.update({"gci_fine": g.gci_fine, "order_p": g.p, "phi_extrapolated_arcmin": g.phi_extrapolated,
                            "monotone": g.monotone, "asymptotic": g.asymptotic, "note": g.note})
        out.append(row)
    return pd.DataFrame(out)


def convergence_stage(default_lost_motion, other_rows, default_refinement: float, out, provenance: dict,
                      meta: dict) -> pd.DataFrame:
    default = pd.read_parquet(default_lost_motion).assign(refinement=float(default_refinement))
    others = pd.concat([pd.read_parquet(p) for p in other_rows], ignore_index=True)
    cols = ["design_id", "refinement", "h_tooth_mm", "lost_motion_arcmin"]
    results = pd.concat([default[cols], others[cols]], ignore_index=True).rename(columns={"h_tooth_mm": "h_mm"})
    return write_convergence(results, out, provenance, meta)


def write_convergence(results: pd.DataFrame, out, provenance: dict, meta: dict) -> pd.DataFrame:
    table = convergence_table(results)
    write_parquet(table, out, provenance=provenance, meta={**meta, "criterion": "two finest meshes differ < 2 %"})
    return table



def deformed_stage(designs_path, design_id: str, unit: str, settings: dict, steps_per_ramp: int, out_png,
                   out_npz, provenance: dict) -> dict:
    """Solve one design keeping the displacement fields; picture of the mesh near the major axis."""
    from .fe import solve_lost_motion
    from .plots import deformed_figure

    params = design_parameters(designs_path, design_id)
    geom = geometry_of(unit, params)
    mesh = _mesh(geom, settings)
    res = solve_lost_motion(geom, mesh, steps_per_ramp=steps_per_ramp, keep_fields=True)
    if res.status != "ok":
        raise RuntimeError(f"{design_id}: solve failed ({res.reason}); no picture of a failed state")
    arrays = {f"{state}:{body}": u for state, per_body in res.fields.items() for body, u in per_body.items()}
    with atomic_path(out_npz) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    pitch = 2 * np.pi * geom.r_fs_pitch / geom.z_fs
    deformed_figure(mesh, res.fields, f"{unit} {design_id} at +4 % T_N (Φ = {res.lost_motion_arcmin:.3f} arcmin), "
                    "true scale", out_png, half_width_mm=2.5 * pitch,
                    xlim=(geom.r_fs_bore - 2 * geom.module, geom.r_cs_root + 3 * geom.module))
    return {"design_id": design_id, "lost_motion_arcmin": res.lost_motion_arcmin}
