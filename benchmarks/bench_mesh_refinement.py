"""One design's lost motion on ever finer meshes, with the FE studies' effects: is Φ converged?

Meshes the design of ``--designs`` (a study's ``designs.parquet``, e.g. the default target's
``results/fe/hd42/designs.parquet``) at each ``--refinements`` factor of ``--mesh`` elements
over the tooth height x thickness (default 10x6, the studies'; half model, 5 steps per ramp),
solves it with ``--effects`` switched on (default: the ``fe.effects`` of ``config.yaml``) and
appends one row per mesh to ``--out`` (CSV: design, mesh, refinement, effects, zone, nodes, status,
Φ, φ+, φ−, teeth in contact, overlap left outside the zones, seconds).  ``--tip-round 0.1`` rounds
the FS and CS tip corners with a radius of 0.1 m (``drive_geometry``'s ``tip_round_m``).  ``--mesh 20x6`` refines the teeth (their size is the finer
of height / 20 and thickness / 6) and what grades from them (the FS rim, the CS rim where four
tooth sizes decide), not the bearing rings.  ``--zone 45`` solves the contacts of the teeth within
45 deg of a major axis only (default: every tooth, as a preload needs) and records the overlap
left outside, to see what the far teeth add to the scatter.  ``--flank-refinement 2.5``
divides every flank into 2.5 times its segments (25 a flank at ``--mesh 10x6``, 30 at 1.25x), the
element size inside the teeth as by default (``build_mesh``'s ``flank_refinement``).  ``--tip-relief 3``
relieves the preloaded tips by 3 times the derived relief instead of the preload's 1.1
(``DriveGeometry.tip_relief``; docs/fe-alternatives.md, "Where the torque is carried, and more tip
relief").
``--design all`` runs every design of ``--designs`` in turn.

Run with one thread, e.g.
  python benchmarks/bench_mesh_refinement.py --unit hd42 --designs results/fe/hd42/designs.parquet \\
      --design hd42-lhs-09 --refinements 1,1.25,1.5,2 --out refine.csv
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

import _one_thread  # noqa: F401,E402  (first: one BLAS thread, hdwf importable)

import pandas as pd
import yaml

from hdwf.drive.design import design_parameters, geometry_of
from hdwf.drive.mesh import build_mesh
from hdwf.fe import solve_lost_motion
from hdwf.validation.effects import model_changes

ROOT = Path(__file__).resolve().parents[1]


def refine(unit: str, designs: Path, design: str, refinements: list[float], effects: dict, out: Path,
           per_tooth: tuple[int, int] = (10, 6), zone_deg: float | None = None, tip_round_m: float = 0.0,
           flank_refinement: float = 1.0, tip_relief: float | None = None) -> None:
    params = design_parameters(designs, design)
    changes = model_changes(effects)
    shape = changes.geometry_part()
    if tip_relief is not None and changes.flank_interference_m > 0:
        # the outline carries the allowance and this relief; the changes then must not ask for theirs
        shape["tip_relief"] = tip_relief
        changes = replace(changes, flank_interference_m=0.0)
    geom = geometry_of(unit, params, **shape, tip_round_m=tip_round_m)
    for ref in refinements:
        t0 = time.perf_counter()
        mesh = build_mesh(geom, *per_tooth, ref, symmetry="half", flank_refinement=flank_refinement)
        res = solve_lost_motion(geom, mesh, steps_per_ramp=5, changes=changes, zone_deg=zone_deg)
        rec = {"design": design, "mesh": "x".join(map(str, per_tooth)), "refinement": ref, "effects": json.dumps(effects),
               "tip_round_m": tip_round_m, "tip_relief": geom.tip_relief, "flank_refinement": flank_refinement,
               "flank_segments": mesh.sizes["n_flank"],
               "zone_deg": zone_deg,   # blank: the default zones (every tooth with a preload)
               "nodes": sum(b.mesh.p.shape[1] for b in mesh.bodies.values()), "status": res.status,
               "phi": res.lost_motion_arcmin, "phi_plus": res.phi_plus_arcmin, "phi_minus": res.phi_minus_arcmin,
               "teeth": res.teeth_in_contact, "loaded_arc_deg": res.loaded_arc_deg,
               "overlap_outside_um": res.overlap_outside_zones_um,
               "seconds": time.perf_counter() - t0}
        if out.exists() and list(pd.read_csv(out, nrows=0).columns) != list(rec):
            raise SystemExit(f"{out} has other columns than this bench writes; give a new --out")
        pd.DataFrame([rec]).to_csv(out, mode="a", header=not out.exists(), index=False)
        print(f"{design} mesh {rec['mesh']} refinement {ref:g}: {res.status} Φ {res.lost_motion_arcmin:.4f} arcmin "
              f"(φ+ {res.phi_plus_arcmin:.4f}, φ− {res.phi_minus_arcmin:.4f}), {rec['teeth']} teeth, "
              f"{rec['nodes']} nodes, {rec['seconds']:.1f} s", flush=True)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unit", choices=("hd42", "hd120"), required=True)
    ap.add_argument("--designs", type=Path, required=True)
    ap.add_argument("--design", required=True, help="a design id of --designs, or all")
    ap.add_argument("--refinements", default="0.75,1,1.25,1.5,2")
    ap.add_argument("--effects", default=None, help='JSON {name: {param: value}}; default: config.yaml fe.effects')
    ap.add_argument("--out", type=Path, default=Path("refine.csv"))
    ap.add_argument("--mesh", default="10x6", help="elements over the tooth height x thickness")
    ap.add_argument("--zone", type=float, default=None, help="half width (deg) of the solved tooth zones")
    ap.add_argument("--tip-round", type=float, default=0.0, help="radius of the tip corners' round, units of m")
    ap.add_argument("--tip-relief", type=float, default=None,
                    help="multiple of the derived tip relief for the preloaded outline (default: the preload's)")
    ap.add_argument("--flank-refinement", type=float, default=1.0,
                    help="multiplies the segments along every flank only (the teeth's element size stays)")
    a = ap.parse_args()
    effects = json.loads(a.effects) if a.effects else \
        yaml.safe_load((ROOT / "config.yaml").read_text())["fe"].get("effects", {})
    per_tooth = tuple(int(n) for n in a.mesh.split("x"))
    ids = pd.read_parquet(a.designs)["design_id"].tolist() if a.design == "all" else [a.design]
    for design_id in ids:
        refine(a.unit, a.designs, design_id, [float(x) for x in a.refinements.split(",")], effects, a.out, per_tooth,
               a.zone, a.tip_round, a.flank_refinement, a.tip_relief)
