"""The per-design stages of the FE studies (rules ``fe_solve`` and ``fe_refined_solve`` in
``workflow/rules/fe.smk``): mesh and solve one design into its row and torque–twist curve.

Some 170 such jobs run in the default target, each a fresh Python process; they write Arrow
tables and never import pandas, which would add a quarter of a second to each one's start.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Mapping

from hdwf.common.io import arrow_row, atomic_path, write_parquet
from hdwf.drive.design import MeshSettings, design_parameters, geometry_of
from hdwf.drive.mesh import DriveMesh
from hdwf.study.fe_design import solve_design
from hdwf.validation.effects import model_changes


@dataclass(frozen=True)
class DesignJob:
    """One design of a study to mesh and solve: where its parameters are, the study's mesh and load
    steps, and the effects switched on in the study's model (``fe.effects``).  ``settings`` also
    carries the tooth contact's options, if set: ``tip_round_m`` (the tip corners' round, units of m)
    and ``flank_layer_fs_pass_only`` (``ModelChanges.flank_layer_fs_pass_only``)."""
    designs_path: str | Path
    design_id: str
    unit: str
    settings: Mapping
    steps_per_ramp: int
    effects: Mapping | None = None

    def model(self):
        """The design's parameters, the switched-on changes and the geometry they shape (the preload
        thickens the teeth)."""
        params = design_parameters(self.designs_path, self.design_id)
        changes = replace(model_changes(self.effects),
                          flank_layer_fs_pass_only=bool(self.settings.get("flank_layer_fs_pass_only", False)))
        geom = geometry_of(self.unit, params, **changes.geometry_part(),
                           tip_round_m=float(self.settings.get("tip_round_m", 0.0)))
        return params, changes, geom

    def mesh(self, geom, path: str | None = None) -> DriveMesh:
        """The design's mesh at the job's settings (gmsh's ``.msh`` written to ``path`` if given)."""
        return MeshSettings.from_mapping(self.settings).mesh(geom, path=path)


def _mesh_to(job: DesignJob, geom, out_msh) -> DriveMesh:
    """Mesh a design's geometry, writing gmsh's ``.msh`` for review; returns the mesh."""
    with atomic_path(out_msh) as tmp_msh:
        # gmsh picks the format from the extension, so the temporary name keeps ".msh".
        tmp_named = tmp_msh.with_suffix(".msh")
        try:
            mesh = job.mesh(geom, path=str(tmp_named))
            tmp_named.replace(tmp_msh)
        finally:    # a mesh that failed leaves no hidden file beside the results
            tmp_named.unlink(missing_ok=True)
    return mesh


@dataclass(frozen=True)
class DesignOutputs:
    """Where one design's solve writes: its mesh (``.msh``), its row and its torque–twist curve."""
    msh: str | Path
    row: str | Path
    curve: str | Path


def solve_stage(job: DesignJob, out: DesignOutputs, provenance: dict) -> dict:
    """Mesh one design and solve it into its row and torque–twist curve (Parquet each), with the
    study's switched-on effects.  One job does both: the mesh takes a second or two, less than a
    job of its own spends starting and passing it on."""
    params, changes, geom = job.model()   # the preload reshapes the outline
    t0 = time.perf_counter()
    mesh = _mesh_to(job, geom, out.msh)
    mesh_s = time.perf_counter() - t0
    row, curve = solve_design(job.unit, params, mesh, job.steps_per_ramp, job.design_id, changes=changes)
    row["mesh_s"] = mesh_s
    write_parquet(arrow_row(row), out.row, provenance=provenance, meta={"unit": job.unit})
    write_parquet(curve, out.curve, provenance=provenance, meta={"unit": job.unit})
    return row


def refined_solve_stage(job: DesignJob, out, provenance: dict) -> dict:
    """Mesh and solve one design at another refinement (mesh-convergence runs); one row out."""
    params, changes, geom = job.model()
    row, _ = solve_design(job.unit, params, job.mesh(geom), job.steps_per_ramp, job.design_id, changes=changes)
    row["refinement"] = float(job.settings["refinement"])
    write_parquet(arrow_row(row), out, provenance=provenance, meta={"unit": job.unit})
    return row
