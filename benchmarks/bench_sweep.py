"""Lost motion of one design against one design variable: Phi, the FS push and where the torque goes.

Solves a base design (HD 42 or HD 120, Table 3's nominal design unless given) at every value of one of
d_mm, D_mm, Gr_mm, rFS_mm, rCS_mm, bare or with the preloaded engagement (``--preload DELTA``,
``--tip-relief`` its multiple of the derived relief, default the studies' ``PRELOAD_TIP_RELIEF``),
and prints per value: Phi (and phi, phi'), the FS bore's radial push at the major axis after the
mount, the teeth in contact at +T and ``loaded_arc_deg`` (the loaded tooth farthest from a major
axis: beyond about 45 deg a tip crossing in the exit zone). ``--out`` appends the rows to a CSV.
``--deflection KAPPA --addendum-frac A`` solves the other preload, a deeper cam
(``DriveGeometry.deflection_coeff``), instead of or with the flank allowance; ``--offsets radial``
reads r_FS, r_CS as rack shifts (``DriveGeometry.offset_direction``). ``--studies-model`` solves
the model of the ``fe`` studies (``config.yaml``'s ``fe.effects``) instead of ``--preload``, and
``--fit`` also prints the FS fit on the bearing's outer ring: the 1-degree bins closed (gap at the
bin's centre below 0.05 um) after the mount and at +T, and the FS bore's largest inward and outward radial motion
from the mount to +T, with their angles from the major axis (docs/fe-model.md, "HD 42's R²").

Examples (docs/fe-alternatives.md, "Where the torque is carried"; docs/fe-model.md, "HD 42's R²"):
  OMP_NUM_THREADS=1 python benchmarks/bench_sweep.py --unit hd42 --base rFS_mm=0.016,rCS_mm=0.016 \\
      --vary d_mm=31.0,31.004,31.008,31.012,31.016 --preload 0.157
  OMP_NUM_THREADS=1 python benchmarks/bench_sweep.py --unit hd42 --base rFS_mm=0.014,rCS_mm=0.014 \\
      --vary D_mm=42.0,41.996,41.992 --studies-model --fit --steps-per-ramp 5
"""

from __future__ import annotations

import argparse
from pathlib import Path

import _one_thread  # noqa: F401,E402  (first: one BLAS thread, hdwf importable)
from _rows import append_rows
from _cli import add_shape_arguments, assignments, check_names, shape_of

import numpy as np
import pandas as pd

from hdwf.config import load_config
from hdwf.drive.design import geometry_of
from hdwf.drive.mesh import DriveMesh, build_mesh
from hdwf.drive.relief import PRELOAD_TIP_RELIEF
from hdwf.fe import ModelChanges, solve_lost_motion
from hdwf.study.paper import load_bounds
from hdwf.validation.effects import model_changes

ROOT = Path(__file__).resolve().parents[1]
FIT_BIN_DEG = np.arange(0.0, 180.0, 1.0)   # the half model's fit bins' centres (contact_rows.fit_rows: 1-degree arcs)
FIT_CLOSED_UM = 0.05


def _radius_on_bins(mesh: DriveMesh, body: str, node_set: str, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Deformed radius and radial displacement (mm) of a circular boundary at the fit bins' centres (point values,
    not the bins' arc means)."""
    bm = mesh.bodies[body]
    ids = bm.node_sets[node_set]
    x, y = bm.mesh.p[:, ids]
    r = np.hypot(x, y)
    ur = (u[body][0, ids] * x + u[body][1, ids] * y) / r
    angle = np.degrees(np.arctan2(y, x)) % 180.0
    return (np.interp(FIT_BIN_DEG, angle, r + ur, period=180.0),
            np.interp(FIT_BIN_DEG, angle, ur, period=180.0))


def fit_state(mesh: DriveMesh, fields: dict) -> dict:
    """The FS bore on the outer ring after the mount (``wg``) and at +T (``plus``): bins closed, and
    the FS bore's largest inward / outward radial motion between the two states and their angles."""
    out, bore_ur = {}, {}
    for state in ("wg", "plus"):
        fs_r, fs_ur = _radius_on_bins(mesh, "fs", "fs_bore", fields[state])
        or_r, _ = _radius_on_bins(mesh, "or", "or_outer", fields[state])
        out[f"fit_closed_{state}"] = int(np.sum((fs_r - or_r) * 1e3 < FIT_CLOSED_UM))
        bore_ur[state] = fs_ur * 1e3
    motion = bore_ur["plus"] - bore_ur["wg"]
    return {**out, "bore_in_um": float(motion.min()), "bore_in_deg": float(FIT_BIN_DEG[motion.argmin()]),
            "bore_out_um": float(motion.max()), "bore_out_deg": float(FIT_BIN_DEG[motion.argmax()])}


def sweep(unit: str, base: dict[str, float], name: str, values: list[float], preload: float,
          relief: float, mesh_size: tuple[int, int], steps_per_ramp: int,
          shape: dict | None = None, changes: ModelChanges | None = None, fit: bool = False) -> pd.DataFrame:
    """``changes`` (the studies' model) replaces ``preload`` and ``relief``; ``fit`` adds ``fit_state``."""
    nominal = load_bounds(ROOT / "data" / "paper", unit).loc["nominal"].to_dict()
    reshape = (changes.geometry_part() if changes is not None
               else {"interference_m": preload, "tip_relief": relief if preload > 0 else 0.0})
    rows = []
    for value in values:
        params = {**nominal, **base, name: value}
        g = geometry_of(unit, params, **reshape, **(shape or {}))
        mesh = build_mesh(g, elements_over_height=mesh_size[0], elements_over_thickness=mesh_size[1],
                          symmetry="half")
        r = solve_lost_motion(g, mesh, steps_per_ramp=steps_per_ramp, changes=changes, keep_fields=fit)
        row = {"unit": unit, **params, "interference_m": g.interference_m, "tip_relief": g.tip_relief,
               "studies_model": changes is not None,
               "deflection_coeff": g.deflection_coeff, "offset_direction": g.offset_direction,
               "status": r.status, "phi": r.lost_motion_arcmin, "phi_plus": r.phi_plus_arcmin,
               "phi_minus": r.phi_minus_arcmin, "push_um": r.wg_deflection_um,
               "teeth": r.teeth_in_contact, "loaded_arc_deg": r.loaded_arc_deg, "solve_s": r.solve_s}
        if fit and r.status == "ok":
            row.update(fit_state(mesh, r.fields))
        rows.append(row)
        model = "the studies' model" if changes is not None else f"δ={g.interference_m:g} m relief {g.tip_relief:g}"
        print(f"{unit} {name}={value:g} κ={g.deflection_coeff:g} {model}: {r.status} "
              f"Φ {r.lost_motion_arcmin:.4f} arcmin (+{r.phi_plus_arcmin:.4f} / −{r.phi_minus_arcmin:.4f}), "
              f"push {r.wg_deflection_um:.1f} µm, teeth {r.teeth_in_contact} out to {r.loaded_arc_deg:.1f}°, "
              f"{r.solve_s:.1f} s {r.reason[:100]}", flush=True)
        if "fit_closed_wg" in row:
            print(f"    fit bins closed {row['fit_closed_wg']}/180 at the mount, {row['fit_closed_plus']}/180 at +T; "
                  f"FS bore mount → +T: {row['bore_in_um']:+.2f} µm at {row['bore_in_deg']:.1f}°, "
                  f"{row['bore_out_um']:+.2f} µm at {row['bore_out_deg']:.1f}°", flush=True)
    return pd.DataFrame(rows)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unit", choices=("hd42", "hd120"), default="hd42")
    ap.add_argument("--base", default="", help="design variables off nominal, e.g. rFS_mm=0.016,rCS_mm=0.016")
    ap.add_argument("--vary", required=True, help="NAME=v1,v2,... e.g. d_mm=31.0,31.008,31.016")
    model = ap.add_mutually_exclusive_group()
    model.add_argument("--preload", type=float, default=0.0, help="interference_m (0: bare section)")
    model.add_argument("--studies-model", action="store_true", help="config.yaml's fe.effects")
    ap.add_argument("--tip-relief", type=float, default=PRELOAD_TIP_RELIEF)
    ap.add_argument("--mesh", default="10x6", help="elements over the tooth height x thickness")
    ap.add_argument("--steps-per-ramp", type=int, default=1)
    add_shape_arguments(ap)
    ap.add_argument("--fit", action="store_true", help="also the FS fit on the outer ring (fit_state)")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    name, _, vals = a.vary.partition("=")
    check_names([name])
    df = sweep(a.unit, assignments(a.base), name, [float(v) for v in vals.split(",")], a.preload, a.tip_relief,
               tuple(int(n) for n in a.mesh.split("x")), a.steps_per_ramp,
               shape_of(a),
               changes=model_changes(load_config(ROOT / "config.yaml")["fe"]["effects"]) if a.studies_model else None,
               fit=a.fit)
    if a.out is not None:
        append_rows(a.out, df)
