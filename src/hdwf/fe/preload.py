"""Preloaded tooth engagement: the wave generator mounted with the teeth in (a preload ramp).

With a tooth-thickness allowance (``DriveGeometry.interference_m`` > 0) or a deeper cam
(``deflection_coeff`` > 1; ``DriveGeometry.preloaded``) the wave generator presses the FS
teeth into the CS spaces: after the wave generator alone is
mounted (``cycle``, no teeth) the teeth overlap their CS spaces by up to the allowance
(tens of micrometres), and pushing them apart moves the FS inwards by several times that
(a wedge of flank angle alpha gives delta / sin alpha radially).  Tooth rows linearised
once at the overlapping state slide off their segments on that path, and the re-detected
gaps then miss by micrometres.  So the overlap is ramped in, as an interference-fit step
of a general FE code does it: every tooth gap is first held back by the largest overlap
h0 (nothing penetrates), h is lowered to 0 in steps of at most ``RAMP_STEP_M`` modules,
and at every step the tooth and cam rows are re-detected at the current deformed state
and re-linearised until the re-detected gap of every pair near contact equals its
linearisation to ``GEO_TOL`` (0.05 um; ``relinearise.settle``).  At h = 0 that is the true
gap.  The tooth rows keep one slave-node set (every tooth node of the engagement zones), so
a pair keeps its identity and its cached compliance column is only renewed when its row
changed.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from hdwf.fe.contact_geometry import boundary_edge_normals, closest_segments
from hdwf.fe.contact_rows import tooth_rows
from hdwf.fe.changes import ModelChanges
from hdwf.fe.friction import FlankFriction, NoFriction, flank_law
from hdwf.fe.model import LostMotionModel
from hdwf.fe.relinearise import GEO_MAX_IT, GEO_TOL, held_back, penetration, settle
from hdwf.fe.solver import ContactFailure, LevelSolution

RAMP_STEP_M = 0.05   # largest drop of the held-back overlap per ramp step, in modules
STEP_TOL = 5e-4      # mm: re-detected minus linearised gap at the intermediate ramp steps
PRELOAD_ZONE_DEG = 90.0   # a preload engages far more teeth: watch every tooth
RAMP_CUTBACKS = 3    # a ramp that fails is run again in steps halved, up to 3 times


def _ramp_step(model: LostMotionModel, level: LevelSolution, hold: float, tol: float
               ) -> tuple[LevelSolution, float]:
    """Solve one ramp step (held-back overlap ``hold``) and settle its gaps to ``tol``."""
    level = model.solve_level(0.0, level.active)
    level, err, ok = settle(model, level, 0.0, tol, hold)
    if not ok:
        raise ContactFailure(f"preload ramp: tooth gaps re-detected {err * 1000:.3f} um off their "
                             f"linearisation after {GEO_MAX_IT} re-linearisations "
                             f"(held-back overlap {hold * 1000:.2f} um)")
    return level, err


def mount_preloaded(model: LostMotionModel, level: LevelSolution,
                    ramp_step_m: float = RAMP_STEP_M) -> tuple[LevelSolution, dict]:
    """Ramp the teeth in on a model whose wave generator is mounted without them.

    Parameters
    ----------
    model : LostMotionModel
        The model after the wave generator stage (its ``rows`` hold cam, balls and fit);
        the tooth rows are added here.
    level : LevelSolution
        The wave-generator-only solution.
    ramp_step_m : float
        Largest drop of the held-back overlap per step, in modules.

    Returns
    -------
    LevelSolution
        The mounted state with the teeth preloaded (true gaps, no penetration beyond
        ``GEO_TOL``).
    dict
        ``overlap_um`` (largest overlap before the ramp), ``ramp_steps``,
        ``geometry_error_um`` (last re-detected minus linearised gap) and
        ``penetration_um`` (largest penetration re-detected at the mounted state).
    """
    st, geom = model.structure, model.geometry
    u = level.u_watch
    rows = tooth_rows(st, geom, u, np.inf)
    nodes = rows.slave_nodes
    overlap = max(0.0, float(-(rows.g0 + rows.G @ u).min()))
    steps = max(1, math.ceil(overlap / (ramp_step_m * geom.module)))
    model.rows["tooth"] = held_back(rows, overlap)
    err, hold = 0.0, overlap
    for k in range(1, steps + 1) if overlap > 0 else ():
        # lower the hold on the current rows (same G: nothing to back-substitute)
        new_hold = overlap * (1.0 - k / steps)
        model.rows["tooth"] = held_back(model.rows["tooth"], new_hold - hold)
        hold = new_hold
        # intermediate steps only have to keep the ramp on its path; the last one is exact
        level, err = _ramp_step(model, level, hold, GEO_TOL if k == steps else STEP_TOL)
    if overlap <= 0:     # no tooth overlaps: one solve with the tooth rows in (true gaps)
        level, err = _ramp_step(model, level, 0.0, GEO_TOL)
    check = tooth_rows(st, geom, level.u_watch, np.inf, nodes=nodes)
    pen = max(0.0, penetration(model, level, check))
    if pen > GEO_TOL + model.solver.settings.tol_gap:
        raise ContactFailure(f"preload ramp: {pen * 1000:.3f} um penetration re-detected at the "
                             "mounted state")
    info = {"overlap_um": overlap * 1000.0, "ramp_steps": steps if overlap > 0 else 0,
            "geometry_error_um": err * 1000.0, "penetration_um": pen * 1000.0}
    return level, info


def mount_with_cutback(model: LostMotionModel, level: LevelSolution) -> tuple[LevelSolution, dict]:
    """``mount_preloaded``; if it fails (an active set that cycles, gaps that do not settle),
    the ramp again from the wave-generator state in steps half as large (at most
    ``RAMP_CUTBACKS`` times), as an FE code cuts back a load step that does not converge.
    Only the rows and the solver state change in a ramp, and before it they hold no tooth
    pair, so their copy is small.  The record gets ``ramp_cutbacks``; the last failure is
    raised.

    The teeth are ramped in without flank friction, which is switched on at the mounted
    state with the loaded flanks sticking (``FlankFriction.sticking_at``): a drive is
    assembled axially (the wave generator pushed into the FS, the CS slid over its teeth),
    so the flanks slide along the axis and keep no tangential force in the section's plane.
    Ramped in the plane with friction, the flanks would slide sideways against it instead."""
    law = model.solver.friction
    model.solver.friction = NoFriction()
    try:
        mounted, info = _ramp_with_cutback(model, level)
    except Exception:
        model.solver.friction = law      # the model as it came, friction and all
        raise
    model.solver.friction = _switched_on(law, model, mounted)
    return mounted, info


def _switched_on(law, model: LostMotionModel, mounted: LevelSolution):
    """The flank law ``law`` at the mounted state: friction with the loaded flanks sticking."""
    if isinstance(law, FlankFriction):
        return FlankFriction.sticking_at(law.mu, model.structure, model.rows, model.solver.working_set,
                                         mounted.pair_ids, mounted.normal_force)
    return law


def with_flank_friction(mounted_model: LostMotionModel, mounted: LevelSolution,
                        changes: ModelChanges) -> LostMotionModel:
    """A fork of a model mounted without friction, with the flank friction of ``changes``
    switched on at its mounted state as ``mount_with_cutback`` does it: the mount of variants
    that differ only in their flank friction is one and the same (frictionless) mount."""
    if replace(mounted_model.changes, flank_friction=changes.flank_friction) != changes:
        raise ValueError("with_flank_friction: the variant differs from the mounted model in more "
                         "than its flank friction")
    model = mounted_model.fork()
    model.changes = changes
    model.solver.friction = _switched_on(flank_law(changes.flank_friction, model.nwatch), model, mounted)
    return model


def _ramp_with_cutback(model: LostMotionModel, level: LevelSolution) -> tuple[LevelSolution, dict]:
    rows, solver = dict(model.rows), model.solver.copy()
    step = RAMP_STEP_M
    for cutback in range(RAMP_CUTBACKS + 1):
        try:
            mounted, info = mount_preloaded(model, level, step)
            info["ramp_cutbacks"] = cutback
            return mounted, info
        except ContactFailure:
            if cutback == RAMP_CUTBACKS:
                raise
            iterations = model.solver.iterations      # the failed ramp's iterations still count
            model.rows, model.solver = dict(rows), solver.copy()
            model.solver.iterations = iterations
            step /= 2.0
    raise AssertionError("unreachable")


def overlap_outside_zones(model: LostMotionModel, level: LevelSolution) -> float:
    """Largest overlap (mm, 0 if none) of FS and CS teeth outside the watched zones.

    Only the teeth of the engagement zones have contact rows; this checks the others at a
    solved state (full displacement fields, the detection of ``tooth_rows``), so that teeth
    that pass through each other unseen are reported instead of silently ignored."""
    disp = model.full_displacements(level, 0.0)
    fs, cs = model.bodies["fs"], model.bodies["cs"]
    x = {"fs": fs.x + disp["fs"], "cs": cs.x + disp["cs"]}
    worst = 0.0
    for slave, master in (("fs", "cs"), ("cs", "fs")):
        sb, mb = model.bodies[slave], model.bodies[master]
        sn = sb.body_mesh.node_sets[f"{slave}_teeth"]
        sn = sn[~np.isin(sn, sb.watch_nodes)]
        if sn.size == 0:
            continue
        E = mb.body_mesh.edge_sets[f"{master}_teeth"]
        gap, _, _ = closest_segments(x[slave][:, sn], x[master][:, E[:, 0]], x[master][:, E[:, 1]],
                                     boundary_edge_normals(mb.body_mesh.mesh, E))
        worst = max(worst, float(-gap.min()))
    return worst
