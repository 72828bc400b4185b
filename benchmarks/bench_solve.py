"""Time one HD 42 design (Table 4, set 8) at the default mesh: median of 3 solves.

Run with one thread, e.g.  OMP_NUM_THREADS=1 python benchmarks/bench_solve.py
Options: a positional refinement (default 1.0), ``--symmetry full|half`` (default full:
the half model uses the drive's 180 deg point symmetry), ``--unit hd42|hd120`` (HD 120
Table 5 set 8), ``--repeats N``, ``--preload DELTA`` (a preloaded engagement alone,
``interference_m`` = DELTA with its tip relief, every tooth watched) and ``--studies-model``
(the effects of ``config.yaml``'s ``fe.effects``, the model of the ``fe`` and ``fe_at_paper`` studies);
``--tip-round 0.1`` rounds the tip corners (``DriveGeometry.tip_round_m``);
``--plain-columns`` back-substitutes the FS's and CS's columns node set by node set, not turned
from one tooth period's (``hdwf.fe.ring_columns``), for comparison.
Prints mesh time, solve_s, factorize_s (one factorisation of every body's stiffness),
their ratio, Phi and the peak resident memory of the process (resource.getrusage).
"""

from __future__ import annotations

import argparse
import resource
import statistics
import sys
import time

import _one_thread  # noqa: F401,E402  (first: one BLAS thread, hdwf importable)

from hdwf.config import load_config  # noqa: E402
from hdwf.fe import solve_lost_motion  # noqa: E402
from hdwf.drive.geometry import drive_geometry  # noqa: E402
from hdwf.drive.mesh import build_mesh  # noqa: E402
from hdwf.validation.effects import model_changes  # noqa: E402
from _workspace import ROOT  # noqa: E402


DESIGNS = {
    "hd42": (("hd42", 31.0151111111, 41.992, 0.0152777778, 0.0144444444, 0.0188888889),
             "HD 42 Table 4 set 8 (paper Phi 1.487 arcmin)"),
    "hd120": (("hd120", 90.020777778, 119.989, 0.024666667, 0.046666667, 0.053333333),
              "HD 120 Table 5 set 8"),
}


def main(repeats: int = 3, refinement: float = 1.0, symmetry: str = "full",
         unit: str = "hd42", preload: float = 0.0, studies_model: bool = False, tip_round_m: float = 0.0) -> None:
    args, label = DESIGNS[unit]
    if studies_model:
        effects = load_config(ROOT / "config.yaml")["fe"]["effects"]
        label += f", the studies' model {effects}"
    else:
        effects = {"preload": {"interference_m": preload}} if preload > 0 else {}
        label += f", preload {preload:g} m" if preload > 0 else ""
    changes = model_changes(effects)
    g = drive_geometry(*args, **changes.geometry_part(), tip_round_m=tip_round_m)
    label += f", tip corners rounded {tip_round_m:g} m" if tip_round_m else ""
    t0 = time.perf_counter()
    mesh = build_mesh(g, refinement=refinement, symmetry=symmetry)
    mesh_s = time.perf_counter() - t0
    runs = []
    for _ in range(repeats):
        r = solve_lost_motion(g, mesh, steps_per_ramp=5, changes=changes)
        if r.status != "ok":
            print(f"FAILED: {r.reason}")
            sys.exit(1)
        runs.append(r)
    solve = statistics.median(r.solve_s for r in runs)
    fact = statistics.median(r.factorize_s for r in runs)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    r = runs[0]
    print(f"design            {label}, symmetry {symmetry}")
    print(f"nodes / dofs      {mesh.n_nodes} / {r.n_dofs}")
    print(f"mesh_s            {mesh_s:.2f}")
    print(f"solve_s (median)  {solve:.2f}   (includes assembly + factorisation)")
    print(f"factorize_s       {fact:.2f}")
    print(f"ratio             {solve / fact:.1f}")
    print(f"peak memory       {peak_mb:.0f} MB")
    print(f"Phi               {r.lost_motion_arcmin:.4f} arcmin (phi {r.phi_plus_arcmin:.4f}, "
          f"phi' {r.phi_minus_arcmin:.4f})")
    print(f"teeth in contact  {r.teeth_in_contact}, max penetration "
          f"{r.max_penetration_um:.4f} um, iterations {r.iterations}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("refinement", nargs="?", type=float, default=1.0)
    ap.add_argument("--symmetry", choices=("full", "half"), default="full")
    ap.add_argument("--unit", choices=tuple(DESIGNS), default="hd42")
    ap.add_argument("--repeats", type=int, default=3)
    model = ap.add_mutually_exclusive_group()
    model.add_argument("--preload", type=float, default=0.0, help="interference_m of the preload (0: bare)")
    model.add_argument("--studies-model", action="store_true", help="config.yaml's fe.effects")
    ap.add_argument("--tip-round", type=float, default=0.0,
                    help="DriveGeometry.tip_round_m: radius of the tip corners' round, units of m")
    ap.add_argument("--plain-columns", action="store_true",
                    help="no columns turned from one period (hdwf.fe.ring_columns), for comparison")
    a = ap.parse_args()
    if a.plain_columns:
        from hdwf.fe.ring_columns import RingColumns
        RingColumns.for_body = classmethod(lambda cls, *args, **kw: None)
    main(repeats=a.repeats, refinement=a.refinement, symmetry=a.symmetry, unit=a.unit, preload=a.preload,
         studies_model=a.studies_model, tip_round_m=a.tip_round)
