"""Where a preloaded section's forces go: tooth, cam and ball loads at the mount and at +T.

Solves one design (a study's ``designs.parquet`` row, or Table 3's nominal changed by ``--base``)
at each ``--preload`` (interference_m; 0 is the bare section, relief 1.1 with a preload as the
studies use it; ``--flank-layer`` L adds the studies' flank layer of L modules) on the half mesh of
``--refinement`` (default 1) and prints, per preload: Φ, the summed normal force of
the tooth pairs, of the cam and of the balls at the mount (the half model's sums doubled: the
whole drive), the most loaded ball and its raceway pressure against ISO 76's 4200 MPa, and the
tangential force the test torque puts on the mesh, T / r_p. ``--bands`` adds the tooth normal
force at the mount and at +T per 10° band from the nearer major axis, split into pairs whose
slave node is an FS flank node and CS tip nodes (the second pass, a CS tip on an FS flank),
over one half of the half model, and the change of the bands' moment on the FS from the mount
to +T (where the test torque is carried). ``--depth`` adds how deep in the CS spaces the loaded pairs
sit at +T: force and pair count per 0.1 m band (``band_m``) of the slave node's deformed radius
minus the CS tip radius (0: on the CS tip's edge; the CS root is about 1.9 m deeper).
It hooks ``hdwf.fe.cycle``'s mount and ±T settling while it runs to read their contact states.

Example (docs/fe-alternatives.md, "The allowance alone as the studies' model"):
  OMP_NUM_THREADS=1 python benchmarks/bench_mount_forces.py --unit hd42 \\
      --designs results/fe/hd42/designs.parquet --design hd42-lhs-23 --preload 0,0.05,0.1,0.157 --bands
  ... --design hd42-lhs-23 --preload 0.157 --depth --out depth.csv
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import _one_thread  # noqa: F401,E402  (first: one BLAS thread, hdwf importable)
from _cli import assignments

import numpy as np
import pandas as pd

import hdwf.fe.cycle as cycle
from hdwf.drive.design import MeshSettings, design_parameters, geometry_of
from scipy.optimize import brentq

from hdwf.fe import ISO76_BALL_PRESSURE_MPA, ball_max_pressure, solve_lost_motion
from hdwf.study.paper import load_bounds
from hdwf.validation.effects import model_changes

ROOT = Path(__file__).resolve().parents[1]


def solve_recording(geom, mesh, changes):
    """``solve_lost_motion`` with the mount's and +T's (model, contact state) recorded."""
    states = {}
    mount, settle = cycle.mount_wave_generator, cycle.settle_teeth

    def recording_mount(model, *args, **kw):
        mounted = mount(model, *args, **kw)
        states["mount"] = (model, mounted.solution)
        return mounted

    def recording_settle(model, torque, level):
        level, pen = settle(model, torque, level)
        if torque > 0:
            states["+T"] = (model, level)
        return level, pen

    cycle.mount_wave_generator, cycle.settle_teeth = recording_mount, recording_settle
    try:
        return solve_lost_motion(geom, mesh, steps_per_ramp=5, changes=changes), states
    finally:
        cycle.mount_wave_generator, cycle.settle_teeth = mount, settle


def kind_sums(level) -> dict[str, float]:
    """Summed normal force (N) of every contact kind in a state."""
    kinds = np.array([k for k, _ in level.pair_ids])
    return {k: float(level.normal_force[kinds == k].sum()) for k in np.unique(kinds)}


def loaded_tooth_pairs(model, level):
    """The loaded tooth pairs of a state: (tooth row, body name, slave node, slave side, normal force)."""
    fs_nodes, cs_nodes = model.rows["tooth"].slave_nodes
    for (kind, i), p in zip(level.pair_ids, level.normal_force):
        if kind == "tooth" and p > 0:
            if i < fs_nodes.size:
                yield i, "fs", fs_nodes[i], "FS flank", p
            else:
                yield i, "cs", cs_nodes[i - fs_nodes.size], "CS tip", p


def tooth_bands(model, level) -> pd.DataFrame:
    """Loaded tooth pairs of a state: angle from the nearer major axis, slave side, force and
    its moment on the FS about the axis (N mm, positive with the test torque; from the rows'
    gap gradient along the FS's rigid rotation, on the rows as the run left them)."""
    G = model.rows["tooth"].G
    fs_rotation = model.structure.watch_vector("fs", model.bodies["fs"].modes["rot"])
    lever = -(G @ fs_rotation)        # a pair pushing the FS with the torque opens as it turns
    out = []
    for row, body, node, side, p in loaded_tooth_pairs(model, level):
        x = model.bodies[body].x[:, node]
        angle = math.degrees(math.atan2(x[1], x[0])) % 180.0
        out.append((min(angle, 180.0 - angle), side, p, p * lever[row]))
    df = pd.DataFrame(out, columns=["angle_deg", "slave", "force_N", "moment_Nmm"])
    df["band"] = pd.cut(df["angle_deg"], np.arange(0, 100, 10))
    return df


def contact_depths(model, level) -> pd.DataFrame:
    """The loaded tooth pairs of the +T state with how deep their slave node sits in the CS space:
    its deformed radius minus the CS tip radius, in modules (0 at the CS tip edge, about 1.9 at
    the CS root), FS flank nodes and CS tip nodes (second pass) apart."""
    g = model.geometry
    u = model.full_displacements(level, g.torque)
    out = [(side, math.hypot(*(model.bodies[body].x[:, node] + u[body][:, node])) - g.r_cs_tip, p)
           for _, body, node, side, p in loaded_tooth_pairs(model, level)]
    df = pd.DataFrame(out, columns=["slave", "depth_mm", "force_N"])
    df["depth_m"] = df["depth_mm"] / g.module
    return df


def _iso_load(geom) -> float:
    """The ball load that gives ISO 76's pressure."""
    return brentq(lambda P: ball_max_pressure(geom, P) - ISO76_BALL_PRESSURE_MPA, 1.0, 1e7)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unit", choices=("hd42", "hd120"), required=True)
    ap.add_argument("--designs", type=Path, help="a study's designs.parquet (with --design)")
    ap.add_argument("--design", help="its design_id")
    ap.add_argument("--base", default="", help="without --designs: Table 3's nominal changed, e.g. rFS_mm=0.01")
    ap.add_argument("--preload", default="0,0.157", help="interference_m values (0: the bare section)")
    ap.add_argument("--flank-layer", type=float, default=0.0,
                    help="with a preload: the flank layer's thickness in modules (the studies' model: "
                         "config.yaml's fe.effects)")
    ap.add_argument("--refinement", type=float, default=1.0)
    ap.add_argument("--bands", action="store_true", help="tooth forces per 10° band at the mount and at +T")
    ap.add_argument("--depth", action="store_true",
                    help="tooth forces at +T by how deep in the CS spaces they sit")
    ap.add_argument("--out", type=Path, help="with --depth: append design, preload, Φ and the share "
                                             "of the tooth force on the CS tips' edges to this CSV")
    a = ap.parse_args()
    if a.designs is not None:
        params = design_parameters(a.designs, a.design)
    else:
        params = {**load_bounds(ROOT / "data" / "paper", a.unit).loc["nominal"].to_dict(), **assignments(a.base)}
    settings = MeshSettings.from_mapping({"elements_over_height": 10, "elements_over_thickness": 6,
                                          "refinement": a.refinement, "symmetry": "half"})
    for delta in (float(x) for x in a.preload.split(",")):
        effects = {"preload": {"interference_m": delta}} if delta > 0 else {}
        if delta > 0 and a.flank_layer > 0:
            effects["flank_layer"] = {"thickness_m": a.flank_layer}
        changes = model_changes(effects)
        geom = geometry_of(a.unit, params, **changes.geometry_part())
        res, states = solve_recording(geom, settings.mesh(geom), changes)
        model, mounted = states["mount"]
        sums = {k: 2 * v for k, v in kind_sums(mounted).items()}     # half model: the whole drive
        print(f"{a.unit} {a.design or a.base or 'nominal'} preload {delta:g} m: {res.status} Φ {res.lost_motion_arcmin:.4f}"
              f" arcmin; at the mount tooth {sums.get('tooth', 0.0):.0f} N, cam {sums.get('cam', 0.0):.0f} N, balls "
              f"{sums.get('ball', 0.0):.0f} N; most loaded ball {res.max_ball_load_N:.0f} N, "
              f"{res.max_ball_pressure_MPa:.0f} MPa (ISO 76: {ISO76_BALL_PRESSURE_MPA:g} MPa at "
              f"{_iso_load(geom):.0f} N); T / r_p = {geom.torque / geom.r_fs_pitch:.1f} N", flush=True)
        if a.bands and delta > 0 and "+T" in states:
            at_mount = tooth_bands(*states["mount"]).groupby(["band", "slave"], observed=True)
            at_plus = tooth_bands(*states["+T"]).groupby(["band", "slave"], observed=True)
            table = pd.DataFrame({"mount_N": at_mount["force_N"].sum(), "plus_T_N": at_plus["force_N"].sum(),
                                  "moment_change_Nmm": at_plus["moment_Nmm"].sum().sub(
                                      at_mount["moment_Nmm"].sum(), fill_value=0.0)})
            print(table.round(1).to_string(), flush=True)
            print(f"  moment change over all bands {table['moment_change_Nmm'].sum():.1f} N mm "
                  f"(the half model's share of T: {geom.torque / 2:.1f} N mm)", flush=True)
        if a.depth and "+T" in states:
            depths = contact_depths(*states["+T"])
            band = np.floor(depths["depth_m"] * 10) / 10
            bands = depths.groupby([depths["slave"], band.rename("band_m")])["force_N"].agg(["sum", "count"])
            at_edge = (depths["slave"] == "CS tip") | (depths["depth_m"] < 0.1)
            edge = depths.loc[at_edge, "force_N"].sum() / depths["force_N"].sum()
            print(f"  at +T by depth in the CS space (m {geom.module:.4f} mm): {edge:.0%} of the tooth force "
                  "within 0.1 m of the CS tips' edges\n" + bands.round(1).to_string(), flush=True)
            if a.out is not None:
                rec = {"unit": a.unit, "design": a.design or a.base or "nominal", "interference_m": delta,
                       "refinement": a.refinement, "status": res.status, "phi": res.lost_motion_arcmin,
                       "tooth_force_plus_T_N": float(bands["sum"].sum()), "loaded_pairs": int(bands["count"].sum()),
                       "cs_tip_edge_share": float(edge)}
                pd.DataFrame([rec]).to_csv(a.out, mode="a", header=not a.out.exists(), index=False)

