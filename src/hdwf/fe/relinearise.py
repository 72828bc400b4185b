"""The tooth and cam rows brought to a solved state: re-detected and re-linearised until they agree.

Contact rows are linear in the displacement about the configuration where they were built.
A state reached by sliding the flanks along each other (the preload ramp pushing the FS
out of the CS spaces, the FS turned at +-T) has to be solved again with rows that match it,
or its gaps are off by fractions of a micrometre.  With preloaded teeth that is not small:
the twist at +-T is the difference of the interference and the elastic retreat of the FS,
and a single re-linearisation at +T made Phi path-dependent (the way back to zero did not
return to the start) and jump from mesh to mesh (``docs/fe-alternatives.md``, "Mesh-convergence
experiments").

``settle`` is the fixed point: at a solved level the rows of every pair near contact are
re-detected (nonlinear gap) and compared with their linearisation; while the error is above
the tolerance the gaps are moved to the re-detected ones (a modified-Newton step that needs
no back-substitution) as long as that halves the error, and otherwise the pairs near
contact are re-paired and re-linearised (new normals and segments).  Its fixed point is the
true gap at the solution.  ``settle_teeth`` applies it at +-T with preloaded teeth;
``redetect_teeth`` is the re-linearisation the bare section and the coning slices keep: the near
pairs re-paired at +-T while they re-detect a penetration, at most three times.  Either way the
teeth are then re-paired from scratch as a check; beyond ``REDETECTED_LIMIT`` the solve fails.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import scipy.sparse as sp

from hdwf.fe.contact_rows import Rows, cam_rows, tooth_rows
from hdwf.fe.model import LostMotionModel
from hdwf.fe.solver import ContactFailure, LevelSolution, Twist

GEO_TOL = 5e-5       # mm: re-detected minus linearised gap of the pairs near contact
# mm: teeth re-found from scratch this far inside each other at +-T fail the solve; 0.5 um is a
# twist error of 0.08 arcmin on HD 42 (0.5 um / r_b), twelve times the solver's resolution of Phi
REDETECTED_LIMIT = 10 * GEO_TOL
GEO_NEAR = 5e-3      # mm: pairs closer than this count as near contact
GEO_MAX_IT = 12      # re-linearisations per state


def held_back(rows: Rows, hold: float) -> Rows:
    """The tooth rows with every gap increased by ``hold`` (mm), an overlap not yet ramped in."""
    return replace(rows, g0=rows.g0 + hold)


def linearisation_error(old: Rows, new: Rows, u: np.ndarray) -> float:
    """Largest |re-detected - linearised| gap at ``u`` over the pairs near contact (mm)."""
    g_old, g_new = old.g0 + old.G @ u, new.g0 + new.G @ u
    near = (g_old < GEO_NEAR) | (g_new < GEO_NEAR)
    return float(np.abs(g_new - g_old)[near].max()) if near.any() else 0.0


def _blend(old: Rows, new: Rows, near: np.ndarray) -> Rows:
    """``new``'s rows where ``near``, ``old``'s elsewhere (same slave nodes, same pairs)."""
    Dn, Df = sp.diags(near.astype(float)), sp.diags((~near).astype(float))
    return replace(new, G=(Dn @ new.G + Df @ old.G).tocsr(), g0=np.where(near, new.g0, old.g0),
                   slip=(Dn @ new.slip + Df @ old.slip).tocsr())


def near_only(old: Rows, new: Rows, u: np.ndarray) -> Rows:
    """``new`` for the pairs near contact, ``old`` for the rest: a far pair's row is renewed
    only once it comes near (each renewed row in the working set costs a back-substitution)."""
    return _blend(old, new, ((old.g0 + old.G @ u) < GEO_NEAR) | ((new.g0 + new.G @ u) < GEO_NEAR))


def gap_only(old: Rows, new: Rows, u: np.ndarray) -> Rows:
    """``old`` with its gaps moved to the re-detected ones at ``u`` (same G: a modified-Newton
    update that needs no back-substitution; its fixed point is the true gap)."""
    return replace(old, g0=old.g0 + (new.g0 + new.G @ u) - (old.g0 + old.G @ u))


def settle(model: LostMotionModel, level: LevelSolution, torque: float | Twist, tol: float,
           hold: float = 0.0) -> tuple[LevelSolution, float, bool]:
    """Re-solve ``level`` (the solution of the model's current rows at ``torque``, N mm)
    with the tooth and cam rows re-detected at the solution until they equal their
    linearisations within ``tol`` (mm).

    The tooth rows keep their slave nodes, so a pair keeps its identity (and its cached
    compliance column while its row is unchanged); ``hold`` (mm) is added to every
    re-detected tooth gap (the preload ramp's overlap not yet ramped in).

    Returns
    -------
    LevelSolution
        The last solution.
    float
        Its linearisation error (mm).
    bool
        Whether that is within ``tol`` (after at most ``GEO_MAX_IT`` updates).
    """
    tooth, cam, err = _redetect(model, level.u_watch, hold)
    prev = math.inf
    for _ in range(GEO_MAX_IT):
        if err < tol:
            break
        u = level.u_watch
        if err > 0.5 * prev:     # the gap updates stopped contracting: re-linearise
            model.replace_rows("tooth", near_only(model.rows["tooth"], tooth, u))
            model.replace_rows("cam", cam)
        else:
            model.rows["tooth"] = gap_only(model.rows["tooth"], tooth, u)
            model.rows["cam"] = gap_only(model.rows["cam"], cam, u)
        prev = err
        level = model.solve_level(torque, level.active)
        tooth, cam, err = _redetect(model, level.u_watch, hold)
    return level, err, err < tol


def _redetect(model: LostMotionModel, u: np.ndarray, hold: float) -> tuple[Rows, Rows, float]:
    """Tooth (same slave nodes, held back by ``hold``) and cam rows re-detected at ``u``, and
    the largest difference from the current rows' linearisation there (mm)."""
    st, geom = model.structure, model.geometry
    tooth = held_back(tooth_rows(st, geom, u, np.inf, nodes=model.rows["tooth"].slave_nodes), hold)
    cam = cam_rows(st, geom, u)
    err = max(linearisation_error(model.rows["tooth"], tooth, u),
              linearisation_error(model.rows["cam"], cam, u))
    return tooth, cam, err


def layer_approach(model: LostMotionModel, level: LevelSolution, check: Rows) -> np.ndarray:
    """The flank layer's approach s p (mm) at each row of ``check`` (tooth rows re-detected at
    ``level``), from the forces of the model's tooth rows on the same slave nodes; zeros
    without a layer.  A re-detected overlap up to this is the layer's, not a penetration."""
    rows = model.rows["tooth"]
    if rows.compliance is None:
        return np.zeros(check.G.shape[0])
    force = np.zeros(rows.G.shape[0])
    compliance = rows.compliance.copy()
    for j, ((kind, i), p) in enumerate(zip(level.pair_ids, level.normal_force)):
        if kind == "tooth":
            force[i] = p
            if level.row_compliance is not None:
                compliance[i] = level.row_compliance[j]
    fs_nodes, cs_nodes = rows.slave_nodes
    key = {("fs", n): a for n, a in zip(fs_nodes.tolist(), (compliance * force)[:fs_nodes.size])}
    key.update({("cs", n): a for n, a in zip(cs_nodes.tolist(), (compliance * force)[fs_nodes.size:])})
    cf, cc = check.slave_nodes
    return np.array([key.get(("fs", n), 0.0) for n in cf.tolist()] + [key.get(("cs", n), 0.0) for n in cc.tolist()])


def penetration(model: LostMotionModel, level: LevelSolution, check: Rows) -> float:
    """Largest penetration (mm) of the re-detected rows ``check`` at ``level``, the layer's
    approach allowed."""
    return float(-(check.g0 + check.G @ level.u_watch + layer_approach(model, level, check)).min())


def settle_teeth(model: LostMotionModel, torque: float,
                 level: LevelSolution) -> tuple[LevelSolution, float]:
    """At +-T (preloaded teeth): the tooth and cam rows settled at the deformed state (re-detected and
    re-linearised until they equal their linearisation within ``GEO_TOL``,
    ``relinearise.settle``), then an independent check that re-pairs every tooth node of
    the zones from scratch (nonlinear gap, no candidate threshold).

    Returns the final level and its re-detected penetration (mm); raises ``ContactFailure``
    if the rows do not settle."""
    level, err, ok = settle(model, level, torque, GEO_TOL)
    if not ok:
        raise ContactFailure(f"torque {torque / 1000:.1f} N m: tooth gaps re-detected "
                             f"{err * 1000:.3f} um off their linearisation after "
                             f"{GEO_MAX_IT} re-linearisations")
    chk = tooth_rows(model.structure, model.geometry, level.u_watch, np.inf)
    return level, penetration(model, level, chk)


def redetect_teeth(model: LostMotionModel, torque: float,
                    level: LevelSolution) -> tuple[LevelSolution, float]:
    """Independent check at +-T: re-detect every FS/CS pair in the zones at the deformed
    configuration (nonlinear gap, no candidate threshold).  Large twists slide the flanks
    along each other; if the linearised pairing then misses more than ``GEO_TOL``, re-pair
    and re-linearise the tooth pairs within ``GEO_NEAR`` of contact about this state and solve the level again.

    Returns the final level and its re-detected penetration (mm), which may stay above
    ``GEO_TOL`` after three re-linearisations: the pairs far from contact keep the mounted
    state's pairing, so the check from scratch can differ from the solved rows' fixed point by a
    few hundredths of a micrometre (0.053 um on a coarse HD 42 specimen, unchanged by five more
    re-linearisations). The caller records it and fails beyond ``REDETECTED_LIMIT``."""
    geom = model.geometry
    for relin in range(4):
        chk = tooth_rows(model.structure, geom, level.u_watch, np.inf)
        pen_nl = penetration(model, level, chk)
        if pen_nl <= GEO_TOL or relin == 3:
            break
        tr = model.rows["tooth"]
        new = tooth_rows(model.structure, geom, level.u_watch, np.inf, nodes=tr.slave_nodes)
        # only pairs at or near contact are re-linearised; the open flanks
        # keep the WG-state pairing, which is the right one for the way back
        model.replace_rows("tooth", _blend(tr, new, (tr.g0 + tr.G @ level.u_watch) < GEO_NEAR))
        level = model.solve_level(torque, level.active)
    return level, pen_nl
