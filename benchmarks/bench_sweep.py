"""Lost motion of one design against one design variable: Phi, the FS push and where the torque goes.

Solves a base design (HD 42 or HD 120, Table 3's nominal design unless given) at every value of one of
d_mm, D_mm, Gr_mm, rFS_mm, rCS_mm, bare or with the preloaded engagement (``--preload DELTA``,
``--tip-relief`` its multiple of the derived relief, default the studies' ``PRELOAD_TIP_RELIEF``),
and prints per value: Phi (and phi, phi'), the FS bore's radial push at the major axis after the
mount, the teeth in contact at +T and ``loaded_arc_deg`` (the loaded tooth farthest from a major
axis: beyond about 45 deg a tip crossing in the exit zone). ``--out`` appends the rows to a CSV.
``--deflection KAPPA --addendum-frac A`` solves the other preload, a deeper cam
(``DriveGeometry.deflection_coeff``), instead of or with the flank allowance; ``--offsets radial``
reads r_FS, r_CS as rack shifts (``DriveGeometry.offset_direction``).

Example (docs/fe-alternatives.md, "Where the torque is carried"):
  OMP_NUM_THREADS=1 python benchmarks/bench_sweep.py --unit hd42 --base rFS_mm=0.016,rCS_mm=0.016 \\
      --vary d_mm=31.0,31.004,31.008,31.012,31.016 --preload 0.157
"""

from __future__ import annotations

import argparse
from pathlib import Path

import _one_thread  # noqa: F401,E402  (first: one BLAS thread, hdwf importable)
from _rows import append_rows
from _cli import add_shape_arguments, assignments, check_names, shape_of

import pandas as pd

from hdwf.drive.design import geometry_of
from hdwf.drive.mesh import build_mesh
from hdwf.drive.relief import PRELOAD_TIP_RELIEF
from hdwf.fe import solve_lost_motion
from hdwf.study.paper import load_bounds

ROOT = Path(__file__).resolve().parents[1]


def sweep(unit: str, base: dict[str, float], name: str, values: list[float], preload: float,
          relief: float, mesh_size: tuple[int, int], steps_per_ramp: int,
          shape: dict | None = None) -> pd.DataFrame:
    nominal = load_bounds(ROOT / "data" / "paper", unit).loc["nominal"].to_dict()
    rows = []
    for value in values:
        params = {**nominal, **base, name: value}
        g = geometry_of(unit, params, interference_m=preload, tip_relief=relief if preload > 0 else 0.0,
                        **(shape or {}))
        mesh = build_mesh(g, elements_over_height=mesh_size[0], elements_over_thickness=mesh_size[1],
                          symmetry="half")
        r = solve_lost_motion(g, mesh, steps_per_ramp=steps_per_ramp)
        rows.append({"unit": unit, **params, "interference_m": preload, "tip_relief": g.tip_relief,
                     "deflection_coeff": g.deflection_coeff, "offset_direction": g.offset_direction,
                     "status": r.status, "phi": r.lost_motion_arcmin, "phi_plus": r.phi_plus_arcmin,
                     "phi_minus": r.phi_minus_arcmin, "push_um": r.wg_deflection_um,
                     "teeth": r.teeth_in_contact, "loaded_arc_deg": r.loaded_arc_deg, "solve_s": r.solve_s})
        print(f"{unit} {name}={value:g} κ={g.deflection_coeff:g} δ={preload:g} m relief {g.tip_relief:g}: {r.status} "
              f"Φ {r.lost_motion_arcmin:.4f} arcmin (+{r.phi_plus_arcmin:.4f} / −{r.phi_minus_arcmin:.4f}), "
              f"push {r.wg_deflection_um:.1f} µm, teeth {r.teeth_in_contact} out to {r.loaded_arc_deg:.1f}°, "
              f"{r.solve_s:.1f} s {r.reason[:100]}", flush=True)
    return pd.DataFrame(rows)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unit", choices=("hd42", "hd120"), default="hd42")
    ap.add_argument("--base", default="", help="design variables off nominal, e.g. rFS_mm=0.016,rCS_mm=0.016")
    ap.add_argument("--vary", required=True, help="NAME=v1,v2,... e.g. d_mm=31.0,31.008,31.016")
    ap.add_argument("--preload", type=float, default=0.0, help="interference_m (0: bare section)")
    ap.add_argument("--tip-relief", type=float, default=PRELOAD_TIP_RELIEF)
    ap.add_argument("--mesh", default="10x6", help="elements over the tooth height x thickness")
    ap.add_argument("--steps-per-ramp", type=int, default=1)
    add_shape_arguments(ap)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    name, _, vals = a.vary.partition("=")
    check_names([name])
    df = sweep(a.unit, assignments(a.base), name, [float(v) for v in vals.split(",")], a.preload, a.tip_relief,
               tuple(int(n) for n in a.mesh.split("x")), a.steps_per_ramp,
               shape_of(a))
    if a.out is not None:
        append_rows(a.out, df)
