"""Which body makes a design compliant: Phi with one bearing part at a time made stiffer.

Solves one design (Table 3's nominal, changed by ``--base``) as it is, then with the inner ring,
the outer ring or the balls ``--factor`` times stiffer (the ring's Young's modulus, the balls'
Hertz compliance divided), and prints Phi, the FS push at the major axis after the mount and the
teeth in contact at +T. A diagnostic: it swaps ``hdwf.fe.model.make_body`` and
``ball_compliance_coeff`` for scaled versions while it runs; the library has no such option.
A stiffer ring also resists the cam's ovalisation, so compare only runs whose push agrees.

Example (docs/fe-alternatives.md, "A deeper cam", what the hump is made of):
  OMP_NUM_THREADS=1 python benchmarks/bench_stiffen.py --unit hd42 --base rFS_mm=0.008,rCS_mm=0 \\
      --deflection 1.4 --addendum-frac 0.38
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import _one_thread  # noqa: F401,E402  (first: one BLAS thread, hdwf importable)
from _cli import add_shape_arguments, assignments, shape_of

import hdwf.fe.model as fe_model
from hdwf.drive.design import geometry_of
from hdwf.drive.mesh import build_mesh
from hdwf.drive.relief import PRELOAD_TIP_RELIEF
from hdwf.fe import solve_lost_motion
from hdwf.study.paper import load_bounds

ROOT = Path(__file__).resolve().parents[1]
PARTS = ("none", "ir", "or", "balls")


def solve_stiffened(geom, mesh, part: str, factor: float):
    """``solve_lost_motion`` with ``part`` (a ring, the balls or "none") ``factor`` times stiffer."""
    make_body, ball_coeff = fe_model.make_body, fe_model.ball_compliance_coeff

    def stiff_body(name, body_mesh, material, watch, **kw):
        if name == part:
            material = replace(material, E=material.E * factor)
        return make_body(name, body_mesh, material, watch, **kw)

    fe_model.make_body = stiff_body
    if part == "balls":
        fe_model.ball_compliance_coeff = lambda g, E: ball_coeff(g, E) / factor
    try:
        return solve_lost_motion(geom, mesh, steps_per_ramp=5)
    finally:
        fe_model.make_body, fe_model.ball_compliance_coeff = make_body, ball_coeff


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unit", choices=("hd42", "hd120"), default="hd42")
    ap.add_argument("--base", default="", help="design variables off nominal, e.g. rFS_mm=0.008,rCS_mm=0")
    ap.add_argument("--preload", type=float, default=0.0, help="interference_m (0: none)")
    ap.add_argument("--factor", type=float, default=100.0)
    ap.add_argument("--mesh", default="5x3", help="elements over the tooth height x thickness")
    add_shape_arguments(ap)
    a = ap.parse_args()
    params = {**load_bounds(ROOT / "data" / "paper", a.unit).loc["nominal"].to_dict(), **assignments(a.base)}
    g = geometry_of(a.unit, params, interference_m=a.preload,
                    tip_relief=PRELOAD_TIP_RELIEF if a.preload > 0 else 0.0, **shape_of(a))
    eh, et = (int(n) for n in a.mesh.split("x"))
    mesh = build_mesh(g, elements_over_height=eh, elements_over_thickness=et, symmetry="half")
    for part in PARTS:
        r = solve_stiffened(g, mesh, part, a.factor)
        print(f"{a.unit} {part:>5} x{a.factor:g}: {r.status} Φ {r.lost_motion_arcmin:.4f} arcmin, "
              f"push {r.wg_deflection_um:.1f} µm, teeth {r.teeth_in_contact} {r.reason[:100]}", flush=True)
