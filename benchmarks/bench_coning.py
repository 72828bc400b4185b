"""Coning (quasi-3D slices, ``hdwf.fe.coning``) against the paper's Tables 4/5.

Every design of the table (half mesh ``--mesh``, coarse 5 x 3 by default, as ``bench_preload``;
relieved tips ``--tip-relief``, a flank layer ``--flank-layer``, every tooth watched) is solved
at each ``--interference`` (units of m; a new FS outline, a new mesh) for every coning slope ``--coning`` c and slice count
``--slices`` N; the slices of one design and interference share the mesh, the factorisation
and every slice push two cases have in common.  One row per (design, interference, c, N) is
appended to ``--out``: status (a failed slice fails the case: no number), Phi, the paper's
Phi, the level solves of its slices, and the seconds of that design and interference (shared
by its cases).  The summary prints, per (interference, c, N): ok count, Phi range, median
ratio ours/paper, Spearman, R², dPhi/dr_FS by least squares over the five inputs (the
paper's on the same designs) and the rms of log(ours/paper), the calibration objective
(level and spread at once).

  OMP_NUM_THREADS=1 python benchmarks/bench_coning.py --unit hd42 --sets 1-27 \\
      --interference 0.13,0.145 --coning 0.2,0.4 --slices 4 --out coning_hd42.csv
``--summary-only`` re-reads ``--out``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import _one_thread  # noqa: F401,E402  (first: one BLAS thread, hdwf importable)
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np
import pandas as pd
from scipy.stats import spearmanr

from bench_preload import COLUMNS, ROOT, TABLES, _sets, agreement
from hdwf.drive.geometry import ARCMIN, drive_geometry
from hdwf.drive.mesh import build_mesh
from hdwf.fe.changes import ModelChanges
from hdwf.fe.coning import solve_coned
from hdwf.study.paper import load_bounds


def solve_all(unit: str, sets: list[int], interferences: list[float], cases: list[tuple[float, int]],
              out: Path, tip_relief: float, flank_layer: float = 0.0, mesh_size: tuple[int, int] = (5, 3)):
    table = pd.read_csv(ROOT / "data" / "paper" / TABLES[unit]).set_index("set")
    for s in sets:
        row = table.loc[s]
        for im in interferences:
            g = drive_geometry(unit, *(row[c] for c in COLUMNS), interference_m=im,
                               tip_relief=tip_relief)
            t0 = time.perf_counter()
            mesh = build_mesh(g, elements_over_height=mesh_size[0], elements_over_thickness=mesh_size[1],
                              symmetry="half")
            mesh_s = time.perf_counter() - t0
            t1 = time.perf_counter()
            results = solve_coned(g, mesh, cases, changes=ModelChanges(flank_layer_m=flank_layer))
            solve_s = time.perf_counter() - t1
            recs = []
            for (c, n), r in zip(cases, results):
                recs.append({"unit": unit, "set": s, "interference_m": im, "tip_relief": tip_relief,
                             "flank_layer_m": flank_layer, "mesh": f"{mesh_size[0]}x{mesh_size[1]}",
                             "coning": c, "slices": n, "status": r.status, "reason": r.reason[:200],
                             "phi": r.lost_motion_arcmin, "phi_plus": r.phi_plus_arcmin,
                             "phi_minus": r.phi_minus_arcmin, "phi_paper": row["lost_motion_arcmin"],
                             "levels": r.levels, "evaluations": r.evaluations, "design_solve_s": solve_s,
                             "mesh_s": mesh_s,
                             "pushes": " ".join(f"{k:.4f}" for k in r.pushes)})
                print(f"{unit} set {s:2d} δ={im:.3f} m c={c:g} N={n}: {r.status} "
                      f"Φ {r.lost_motion_arcmin:.4f} (paper {row['lost_motion_arcmin']:.4f}) "
                      f"levels {r.levels} evaluations {r.evaluations} {r.reason[:100]}", flush=True)
            print(f"   design solve {solve_s:.1f} s, mesh {mesh_s:.1f} s", flush=True)
            pd.DataFrame(recs).to_csv(out, mode="a", header=not out.exists(), index=False)


def summary(out: Path, cup_K: float | None = None):
    df = pd.read_csv(out)
    for (unit, im, c, n), d in df.groupby(["unit", "interference_m", "coning", "slices"]):
        table = pd.read_csv(ROOT / "data" / "paper" / TABLES[unit]).set_index("set")
        ok = d[d.status == "ok"]
        if len(ok) < 3:
            print(f"{unit} δ={im:.3f} c={c:g} N={n}: {len(ok)}/{len(d)} ok")
            continue
        a = agreement(table, ok)
        rms = float(np.sqrt(np.mean(np.log(ok.phi / ok.phi_paper) ** 2)))
        per_design = ok.drop_duplicates("set").design_solve_s
        print(f"{unit} δ={im:.3f} m c={c:g} N={n}: {len(ok)}/{len(d)} ok, Φ {ok.phi.min():.3f}–"
              f"{ok.phi.max():.3f}, median ratio {a['ratio']:.3f}, rms log ratio {rms:.3f}, "
              f"Spearman {a['rho']:.3f}, R² {a['r2']:.3f}, "
              f"dΦ/dr_FS {a['slope']:.4f} ({a['paper_slope']:.4f}) arcmin/µm, design solve median "
              f"{per_design.median():.1f} s")
        add, cup = series_cup(unit, ok, cup_K)
        how = "given" if cup_K else "least rms log ratio"
        print(f"   + cup torsion in series ({add:.3f} arcmin, K {cup:.3g} N·m/rad, {how}): median ratio "
              f"{np.median((ok.phi + add) / ok.phi_paper):.3f}, rms log ratio "
              f"{np.sqrt(np.mean(np.log((ok.phi + add) / ok.phi_paper) ** 2)):.3f}, Spearman "
              f"{spearmanr(ok.phi + add, ok.phi_paper)[0]:.3f}, R² {np.corrcoef(ok.phi + add, ok.phi_paper)[0, 1] ** 2:.3f}")


def series_cup(unit: str, ok: pd.DataFrame, cup_K: float | None = None) -> tuple[float, float]:
    """Cup torsion in series: the twist (arcmin) it adds to every Phi and its stiffness K (N m/rad).
    A series spring adds T/K at +T and at -T, exactly (``fs_cup_torsion``), so no solve is
    needed. With ``cup_K`` given, Phi + 2 T / K; else the K whose twist minimises the rms log
    ratio to the paper."""
    nominal = load_bounds(ROOT / "data" / "paper", unit).loc["nominal"]
    torque_Nm = drive_geometry(unit, *nominal[list(COLUMNS)]).torque * 1e-3
    if cup_K:
        return 2.0 * torque_Nm / cup_K / ARCMIN, cup_K
    grid = np.arange(0.0, 1.0, 0.005)
    rms = [np.sqrt(np.mean(np.log((ok.phi + g) / ok.phi_paper) ** 2)) for g in grid]
    add = float(grid[int(np.argmin(rms))])
    return add, (2.0 * torque_Nm / (add * ARCMIN) if add > 0 else np.inf)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unit", choices=tuple(TABLES), default="hd42")
    ap.add_argument("--sets", default="1-27")
    ap.add_argument("--interference", default="0.145")
    ap.add_argument("--coning", default="0.2,0.4", help="coning slopes c")
    ap.add_argument("--slices", default="4", help="slice counts N")
    ap.add_argument("--cases", default="",
                    help="explicit c:N pairs, e.g. 0:1,0.4:4 (instead of --coning x --slices)")
    ap.add_argument("--tip-relief", type=float, default=1.1)
    ap.add_argument("--flank-layer", type=float, default=0.0,
                    help="flank layer thickness in units of m (the studies' model: 3900)")
    ap.add_argument("--mesh", default="5x3", help="elements over tooth height x thickness")
    ap.add_argument("--out", type=Path, default=Path("coning.csv"))
    ap.add_argument("--summary-only", action="store_true")
    ap.add_argument("--cup-K", type=float, default=None,
                    help="summary: cup torsion in series at this K (N m/rad) instead of the least-rms one")
    a = ap.parse_args()
    if a.cases:
        cases = [(float(x.split(":")[0]), int(x.split(":")[1])) for x in a.cases.split(",")]
    else:
        cases = [(float(c), int(n)) for c in a.coning.split(",") for n in a.slices.split(",")]
    if not a.summary_only:
        solve_all(a.unit, _sets(a.sets), [float(x) for x in a.interference.split(",")], cases,
                  a.out, a.tip_relief, a.flank_layer, tuple(int(x) for x in a.mesh.split("x")))
    summary(a.out, a.cup_K)
