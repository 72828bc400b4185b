"""One design of an FE study solved into its study row (Φ and solver facts) and its curve."""

from __future__ import annotations

from typing import Mapping

import numpy as np
import pyarrow as pa

from hdwf.common.io import arrow_table

from hdwf.drive.design import geometry_of
from hdwf.drive.mesh import DriveMesh
from hdwf.fe import solve_lost_motion
from hdwf.fe.changes import ModelChanges

CURVE_COLUMNS = ["design_id", "step", "torque_Nm", "twist_arcmin"]


def solve_design(unit: str, params: Mapping[str, float], mesh: DriveMesh, steps_per_ramp: int, design_id: str,
                 changes: ModelChanges | None = None, **solver_options) -> tuple[dict, pa.Table]:
    """Solve one design; return its lost-motion row and its torque–twist curve.

    Parameters
    ----------
    unit : ``"hd42"`` or ``"hd120"``.
    params : the design's ``d_mm`` … ``rCS_mm``.
    mesh : the design's mesh (``hdwf.drive.design``).
    steps_per_ramp : load steps on each of the four ramps of the torque cycle.
    design_id : the id written into the row and the curve.
    changes : the effects switched on in the study's model (``fe.effects``); a change that reshapes
        the section (the preload) must also be in the geometry ``mesh`` was made from.

    Returns
    -------
    row, curve : a failed solve gives status ``failed: <reason>`` and no Φ (never a silent number).
    """
    changes = ModelChanges() if changes is None else changes
    geom = geometry_of(unit, params, **changes.geometry_part())
    res = solve_lost_motion(geom, mesh, steps_per_ramp=steps_per_ramp, changes=changes, **solver_options)
    ok = res.status == "ok"
    row = {"design_id": design_id, **params,
           "phi_plus_arcmin": res.phi_plus_arcmin if ok else np.nan,
           "phi_minus_arcmin": res.phi_minus_arcmin if ok else np.nan,
           "lost_motion_arcmin": res.lost_motion_arcmin if ok else np.nan,
           "status": "ok" if ok else f"failed: {res.reason}",
           "teeth_in_contact": int(res.teeth_in_contact), "max_penetration_um": float(res.max_penetration_um),
           "max_penetration_redetected_um": float(res.max_penetration_redetected_um),
           "overlap_outside_zones_um": float(res.overlap_outside_zones_um),
           "loaded_arc_deg": float(res.loaded_arc_deg),
           "ball_load_max_N": float(res.max_ball_load_N), "ball_pressure_max_MPa": float(res.max_ball_pressure_MPa),
           "iterations": int(res.iterations), "n_dofs": int(res.n_dofs), "solve_s": float(res.solve_s),
           "factorize_s": float(res.factorize_s), "h_tooth_mm": float(mesh.sizes.get("tooth", np.nan))}
    step = np.asarray(res.step, dtype="int64")
    curve = arrow_table(dict(zip(CURVE_COLUMNS, ([design_id] * step.size, step, np.asarray(res.torque_Nm, float),
                                                 np.asarray(res.twist_arcmin, float)))))
    return row, curve
