"""The lost-motion test on the FE model: mount the wave generator, run 0 -> +T -> 0 -> -T -> 0.

Stage 1 pushes the wave generator into the FS (no teeth, FS rotation pinned); the cam rows
are re-linearised at the deformed configuration until the geometry update is below 1e-6 mm.
With a preload (``DriveGeometry.preloaded``) the teeth are then ramped in at
zero torque (``preload.mount_with_cutback``), every tooth watched.  After stage 1 the teeth
outside the watched zones are checked for overlap (reported, ``overlap_outside_zones_um``).
Stage 2 builds the tooth rows at the deflected configuration, frees the FS rotation and
runs the torque sequence.  At +-T, with preloaded teeth, the tooth and cam rows are settled
at the deformed state: re-detected (nonlinear gap) and re-linearised until every pair near
contact agrees with its linearisation within 0.05 um (``relinearise.settle``; the twist sliding the
flanks along each other must not leave the gaps of the mounted state, or Phi depends on
the load path and the mesh), then every tooth pair is re-paired from scratch as an
independent check (``max_penetration_redetected_um``).  A level that fails is reached through
the torque halfway from the last one (``LostMotionModel.solve_level_stepped``).  The way back
starts from the mount's rows again: rows settled at +T fit that state only.  Frictionless, a
level on the way back is then the way up's problem at that torque (same rows, same load;
elastic contact without friction has one solution), so it is not solved again.  Without preload (and in the coning
slices) the near pairs are re-linearised at +-T while more than 0.05 um penetration is
re-detected (at most three times), and those rows are kept for the way back
(``redetect_teeth``).  Teeth re-found more than 0.5 um inside each other fail the solve.

The frictionless FS is indifferent inside the backlash at zero torque; zero-torque steps
use 1e-3 of the test torque in the direction of the last load (the state an
infinitesimally small friction would leave), documented in the result.  Curve twists are
relative to the first (+0) state.  In the half model every tooth in contact has its image
at +pi, so the count of teeth in contact is doubled.

A coned cup (``ModelChanges.coning_slope`` not 0) is solved by ``hdwf.fe.coning`` as slices in
parallel; its result has the same form.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from hdwf.drive.geometry import ARCMIN, DriveGeometry
from hdwf.drive.mesh import DriveMesh
from hdwf.fe.changes import ModelChanges
from hdwf.fe.contact_rows import ball_rows, cam_rows, fit_rows, tooth_rows
from hdwf.fe.hertz import ball_max_pressure
from hdwf.fe.model import ZONE_DEG, LostMotionModel, SharedBodies
from hdwf.fe.preload import PRELOAD_ZONE_DEG, mount_with_cutback, overlap_outside_zones, with_flank_friction
from hdwf.fe.relinearise import REDETECTED_LIMIT, redetect_teeth, settle_teeth
from hdwf.fe.series import series_output_twist
from hdwf.fe.solver import TOL_GAP, ContactFailure, LevelSolution

ZERO_TORQUE_BIAS = 1e-3  # fraction of the test torque used at the zero-torque steps
EXIT_ARC_DEG = 45.0      # a tooth loaded farther from a major axis is a tip crossing, not the working mesh


@dataclass
class LostMotionResult:
    """The simulated test of one design: the torque-twist curve, Phi and how it was solved."""
    phi_plus_arcmin: float
    phi_minus_arcmin: float
    lost_motion_arcmin: float
    step: np.ndarray
    torque_Nm: np.ndarray
    twist_arcmin: np.ndarray
    teeth_in_contact: int
    max_penetration_um: float
    iterations: int
    status: str
    reason: str
    solve_s: float
    factorize_s: float
    n_dofs: int = 0
    wg_deflection_um: float = float("nan")   # FS bore radial displacement at major axis
    max_penetration_redetected_um: float = float("nan")  # tooth pairs re-found at +-T
    overlap_outside_zones_um: float = float("nan")  # teeth outside the zones, at the mount
    loaded_arc_deg: float = float("nan")   # largest angle from a major axis of a tooth loaded at +T
    max_ball_load_N: float = float("nan")   # the most loaded wave-generator ball at the mount
    max_ball_pressure_MPa: float = float("nan")  # its raceway contact pressure (ISO 76 rates 4200)
    notes: str = ""
    fields: dict | None = None   # with keep_fields: {"wg": {...}, "plus": {...}} body -> (2, n) mm

    @property
    def curve(self) -> dict[str, np.ndarray]:
        return {"step": self.step, "torque_Nm": self.torque_Nm,
                "twist_arcmin": self.twist_arcmin}


@dataclass(frozen=True)
class MountedWaveGenerator:
    """Stage 1 solved: the contact solution and the FS bore's radial push at the major axis."""
    solution: LevelSolution
    deflection_um: float
    preload: dict | None = None        # the preload ramp's record (``mount_preloaded``)
    outside_overlap_um: float = 0.0    # teeth overlapping outside the zones (unsolved)


@dataclass(frozen=True)
class TorqueTest:
    """Stage 2 solved: rim twists (rad) and the checks of the contact solution."""
    twists: np.ndarray
    max_penetration: float             # mm, over every level (balls excluded)
    max_penetration_redetected: float  # mm, tooth pairs re-found at +-T (NaN: not checked)
    teeth_in_contact: int              # at +T
    loaded_arc_deg: float              # at +T: the loaded tooth farthest from a major axis
    fields: dict | None                # displacement fields (keep_fields)


def torque_fractions(steps_per_ramp: int) -> np.ndarray:
    """The test's torque at each step, as a fraction of the test torque: 0 -> 1 -> 0 -> -1 -> 0
    in ``steps_per_ramp`` steps per ramp (4 x ``steps_per_ramp`` + 1 steps)."""
    n = steps_per_ramp
    up = np.linspace(0, 1, n + 1)
    return np.concatenate([up, up[::-1][1:], -up[1:], -up[::-1][1:]])


def mount_wave_generator(model: LostMotionModel,
                          ramp_teeth: bool = False) -> MountedWaveGenerator:
    """Stage 1: the wave generator pushed into the FS (no teeth), FS rotation pinned; with
    ``ramp_teeth`` the teeth are then ramped in (``preload.mount_preloaded``)."""
    geom = model.geometry
    # (the half model's symmetric field has no translations: no modes in stage 1)
    model.mode_list = [] if model.half else [("fs", "tx"), ("fs", "ty"), ("ir", "tx"),
                                             ("ir", "ty"), ("or", "tx"), ("or", "ty")]
    model.rows["ball"] = ball_rows(model.structure, geom)
    model.rows["fit"] = fit_rows(model.structure, geom, model.n_bins)
    u = np.zeros(model.nwatch)
    model.rows["cam"] = cam_rows(model.structure, geom, u)
    state = None
    for geo_it in range(6):
        state = model.solve_level(0.0, state.active if state is not None else None)
        u = state.u_watch
        new = cam_rows(model.structure, geom, u)
        change = np.max(np.abs((new.g0 + new.G @ u) - (model.rows["cam"].g0
                                                        + model.rows["cam"].G @ u)))
        if change < 1e-6 and geo_it > 0:
            break
        model.replace_rows("cam", new)
    else:   # the last solve used rows that no longer fit its state: no silent mount
        raise ContactFailure(f"wave generator mount: cam rows still moved {change * 1000:.4f} um after "
                             f"{geo_it + 1} re-linearisations")
    fs = model.bodies["fs"]
    bore = fs.body_mesh.node_sets["fs_bore"]
    j0 = bore[np.argmin((fs.x[0, bore] - geom.r_fs_bore) ** 2 + fs.x[1, bore] ** 2)]
    j0 = fs.watch_index[0, j0]          # its radial (x) entry in the watch vector
    preload = None
    if ramp_teeth:     # preloaded (or overlapping) teeth: ramp them in (``preload``)
        free_deflection = float(u[j0])
        state, preload = mount_with_cutback(model, state)
        u = state.u_watch
        preload["wg_retreat_um"] = (free_deflection - float(u[j0])) * 1000.0
    return MountedWaveGenerator(state, float(u[j0]) * 1000.0, preload,
                                 overlap_outside_zones(model, state) * 1000.0)


def teeth_in_contact(model: LostMotionModel, level: LevelSolution, kinds: np.ndarray) -> tuple[int, float]:
    """FS teeth with a loaded pair (both halves counted in the half model), and the largest
    angle (deg) of one of them from the nearer major axis: a loaded tooth far out in the exit
    zone (beyond ``EXIT_ARC_DEG``) is a tip crossing, not the working mesh."""
    tr = model.rows["tooth"]
    ti = [i for (kk, i) in level.pair_ids if kk == "tooth"]
    pt = level.normal_force[kinds == "tooth"]
    teeth = np.unique(tr.tooth[np.array(ti, dtype=np.int64)[pt > 0]])
    count = int(teeth.size)
    if model.half:
        count *= 2             # every tooth has its image at +pi
    angle = np.mod(teeth * 360.0 / model.geometry.z_fs, 180.0)
    arc = float(np.minimum(angle, 180.0 - angle).max()) if teeth.size else float("nan")
    return count, arc


def _torque_test(model: LostMotionModel, frac: np.ndarray, mounted: MountedWaveGenerator,
                 fields: dict | None) -> TorqueTest:
    """Stage 2: teeth at the deflected configuration, FS rotation free, the torque sequence."""
    geom = model.geometry
    Tn = geom.torque
    if "tooth" not in model.rows:   # (a preloaded mount has its tooth rows already)
        cand = 0.25 * geom.module + 3 * sum(geom.flank_offsets)
        model.rows["tooth"] = tooth_rows(model.structure, geom, mounted.solution.u_watch, cand)
    model.mode_list = model.mode_list + [("fs", "rot")]
    active = mounted.solution.active
    twists, maxpen, maxpen_nl, tooth_count, arc = [], 0.0, 0.0, 0, float("nan")
    last_sign, last_T = 1.0, 0.0
    # frictionless and preloaded, the way back is the way up's problem (module docstring)
    solved = {} if (geom.preloaded and model.changes.flank_friction == 0.0) else None
    for fraction in frac:
        if abs(fraction) > 1e-12:
            last_sign = math.copysign(1.0, fraction)
            T = fraction * Tn
        else:
            T = ZERO_TORQUE_BIAS * Tn * last_sign
        if solved is not None and T in solved:   # with the warm start it left for the next level
            level, model.solver.last_u, model.solver.ball_loads = solved[T]
        else:
            level = model.solve_level_stepped(T, active, last_T)
            if solved is not None:
                solved[T] = (level, model.solver.last_u, model.solver.ball_loads)
        active, last_T = level.active, T    # the next level's warm start (with the rows it will use)
        at = model
        at_full_torque = abs(abs(fraction) - 1.0) < 1e-12
        if at_full_torque and model.geometry.preloaded:
            # rows settled at +-T fit that state only: settled on a fork, the way back starts
            at = model.fork()     # from the mount's rows (and columns) again
            level, pen_nl = settle_teeth(at, T, level)
            model.solver.iterations = at.solver.iterations   # the count includes the settling
            maxpen_nl = max(maxpen_nl, pen_nl)
        elif at_full_torque:
            level, pen_nl = redetect_teeth(model, T, level)
            active = level.active
            maxpen_nl = max(maxpen_nl, pen_nl)
        if at_full_torque and maxpen_nl > REDETECTED_LIMIT:
            raise ContactFailure(f"torque {T / 1000:.1f} N m: teeth re-found {maxpen_nl * 1000:.3f} um inside each "
                                 f"other, beyond the {REDETECTED_LIMIT * 1000:g} um a solve may leave")
        twists.append(level.twist)
        kinds = np.array([i[0] for i in level.pair_ids])
        geo_mask = kinds != "ball"
        maxpen = max(maxpen, float(-(level.gap[geo_mask]).min()))
        if abs(fraction - 1.0) < 1e-12:
            if fields is not None and "plus" not in fields:
                fields["plus"] = at.full_displacements(level, T)
            tooth_count, arc = teeth_in_contact(at, level, kinds)
    return TorqueTest(np.array(twists), maxpen, maxpen_nl, tooth_count, arc, fields)


def lost_motion_result(model: LostMotionModel, changes: ModelChanges, frac: np.ndarray,
                       mounted: MountedWaveGenerator, test: TorqueTest, t0: float) -> LostMotionResult:
    """The result of a solved test: the curve at the output (series elements of ``changes`` added),
    Phi, and the record of the mount and the test."""
    Tn = model.geometry.torque
    tw = series_output_twist(test.twists, frac * Tn, changes) / ARCMIN
    tw = tw - tw[0]
    kp = int(np.argmin(np.abs(frac - 1.0)))
    km = int(np.argmin(np.abs(frac + 1.0)))
    phi_p, phi_m = float(tw[kp]), float(-tw[km])
    # NaN where the check was not made (a coned cup's slices keep their settled gaps)
    pen = test.max_penetration_redetected
    redetected_um = max(0.0, pen) * 1000.0 if math.isfinite(pen) else float("nan")
    mount = mounted.solution
    ball_N = float(mount.normal_force[[k == "ball" for k, _ in mount.pair_ids]].max(initial=0.0))
    return LostMotionResult(
        phi_plus_arcmin=phi_p, phi_minus_arcmin=phi_m,
        lost_motion_arcmin=phi_p + phi_m, step=np.arange(frac.size),
        torque_Nm=frac * Tn / 1000.0, twist_arcmin=tw, teeth_in_contact=test.teeth_in_contact,
        max_penetration_um=max(0.0, test.max_penetration) * 1000.0, iterations=model.iterations,
        status="ok", reason="", solve_s=time.perf_counter() - t0,
        factorize_s=model.factorize_s, n_dofs=model.n_dofs, wg_deflection_um=mounted.deflection_um,
        max_penetration_redetected_um=redetected_um,
        overlap_outside_zones_um=mounted.outside_overlap_um, loaded_arc_deg=test.loaded_arc_deg,
        max_ball_load_N=ball_N, max_ball_pressure_MPa=ball_max_pressure(model.geometry, ball_N, model.material.E),
        notes=(f"zero-torque steps at {ZERO_TORQUE_BIAS:g} T_test towards the last load; "
               f"tooth penetration re-detected at the deformed state at +-T: "
               + (f"{redetected_um:.4f} um" if math.isfinite(redetected_um) else "not checked")
               + "; teeth outside the solved zones overlap by "
               f"{mounted.outside_overlap_um:.2f} um at the mount" + _preload_note(mounted.preload)),
        fields=test.fields)


def _preload_note(preload: dict | None) -> str:
    if preload is None:
        return ""
    cut = preload.get("ramp_cutbacks", 0)
    return (f"; preload ramp: overlap {preload['overlap_um']:.2f} um in {preload['ramp_steps']} "
            f"steps" + (f" (step halved {cut}x: the first ramp failed)" if cut else "")
            + f", re-detected penetration at the mount {preload['penetration_um']:.4f} um")


def failed_result(exc: Exception, model: LostMotionModel | None, t0: float) -> LostMotionResult:
    """Status "failed" with the exception as the reason, and no number."""
    nan, empty = float("nan"), np.array([])
    return LostMotionResult(
        phi_plus_arcmin=nan, phi_minus_arcmin=nan, lost_motion_arcmin=nan,
        step=empty, torque_Nm=empty, twist_arcmin=empty, teeth_in_contact=0,
        max_penetration_um=nan, iterations=model.iterations if model is not None else 0,
        status="failed", reason=f"{type(exc).__name__}: {exc}",
        solve_s=time.perf_counter() - t0,
        factorize_s=model.factorize_s if model is not None else nan,
        n_dofs=model.n_dofs if model is not None else 0)


def _zone(geom: DriveGeometry, zone_deg: float | None) -> float:
    """The engagement zones' half width (deg): ``zone_deg``, else by whether teeth are preloaded."""
    if zone_deg is not None:
        return zone_deg
    return PRELOAD_ZONE_DEG if geom.preloaded else ZONE_DEG


def _check_geometry(geom: DriveGeometry, changes: ModelChanges) -> None:
    """Changes that reshape the section (``ModelChanges.geometry_part``) must come with a geometry
    made with them: the solve cannot thicken the teeth of a mesh it is given."""
    if changes.flank_interference_m > 0:
        need = changes.geometry_part()
        if (need["interference_m"], need["tip_relief"]) != (geom.interference_m, geom.tip_relief):
            raise ValueError(f"changes with {need} need a geometry made with them (ModelChanges.geometry_part); "
                             f"this one has interference_m={geom.interference_m}, tip_relief={geom.tip_relief}")


def solve_lost_motion(geom: DriveGeometry, mesh: DriveMesh, steps_per_ramp: int = 5,
                      E: float | None = None, max_iter: int = 200,
                      tol_gap: float = TOL_GAP, keep_fields: bool = False,
                      changes: ModelChanges | None = None,
                      zone_deg: float | None = None) -> LostMotionResult:
    """Simulate the lost-motion test 0 -> +T -> 0 -> -T -> 0 (WG locked, CS fixed).

    Parameters
    ----------
    geom : DriveGeometry
        The design.
    mesh : DriveMesh
        Its mesh (full or half section).
    steps_per_ramp : int
        Load steps per ramp (4 ramps).
    E : float, optional
        Young's modulus instead of ``geom.E`` (e.g. the rigid-body limit).
    max_iter : int
        Active-set iterations per load level; a run that hits it returns status "failed".
    tol_gap : float
        Largest penetration accepted (mm).
    keep_fields : bool
        Also return the displacement of every node after the wave generator is mounted
        (``wg``) and at +T (``plus``).
    changes : ModelChanges, optional
        Physical additions to the baseline model (set by ``hdwf.validation.effects``).
    zone_deg : float, optional
        Half width (deg) of the tooth zones about the major axis whose contacts are
        solved; default 35 without preload, every tooth (90) with ``geom.preloaded``
        (a preload engages teeth far beyond 35 deg).

    Returns
    -------
    LostMotionResult
        Status "ok", or "failed" with a reason and no number.
    """
    changes = ModelChanges() if changes is None else changes
    _check_geometry(geom, changes)
    if changes.coning_slope != 0.0:
        return _coned(geom, mesh, steps_per_ramp, changes, zone_deg, keep_fields)
    t0 = time.perf_counter()
    frac = torque_fractions(steps_per_ramp)
    model = None
    try:
        model = LostMotionModel(geom, mesh, E=E, max_iter=max_iter, tol_gap=tol_gap,
                                changes=changes, zone_deg=_zone(geom, zone_deg))
        # the ramp for a preload, and for any zones wider than today's (teeth beyond 35 deg
        # can overlap at the mount); today's 35 deg zones keep today's path
        ramp = geom.preloaded or zone_deg not in (None, ZONE_DEG)
        mounted = mount_wave_generator(model, ramp)
        fields = {"wg": model.full_displacements(mounted.solution, 0.0)} if keep_fields else None
        test = _torque_test(model, frac, mounted, fields)
        return lost_motion_result(model, changes, frac, mounted, test, t0)
    except Exception as exc:   # any failure is reported, never a silent number
        return failed_result(exc, model, t0)


def solve_lost_motion_variants(geom: DriveGeometry, mesh: DriveMesh, steps_per_ramp: int,
                               variants: list[ModelChanges], shared: SharedBodies | None = None
                               ) -> list[LostMotionResult]:
    """The test for several model variants of one design, sharing what they can.

    The bodies are assembled and factorised and the wave generator mounted once; each
    variant then switches its tooth-stage changes on a copy (a new CS factorisation only
    when it changes the CS support) and runs the torque sequence. Variants that differ only
    in their series elements (``ModelChanges.fe_part``) share one torque sequence: those
    elements act on its output. Same numbers as ``solve_lost_motion`` for each variant up to
    round-off.

    Parameters
    ----------
    geom, mesh, steps_per_ramp : DriveGeometry, DriveMesh, int
        The design, its mesh and the load steps per ramp.
    variants : list of ModelChanges
        The model variants.
    shared : SharedBodies, optional
        Bodies built for earlier outlines of the design that the models may take.

    Returns
    -------
    list of LostMotionResult
        One per variant, in order.
    """
    for ch in variants:
        _check_geometry(geom, ch)
    if any(ch.coning_slope != 0.0 for ch in variants):
        # the coned cup mounts its own slices: solved apart, once per distinct variant
        coned = {ch: _coned(geom, mesh, steps_per_ramp, ch) for ch in variants if ch.coning_slope != 0.0}
        rest = [ch for ch in variants if ch.coning_slope == 0.0]
        solved = dict(zip(rest, solve_lost_motion_variants(geom, mesh, steps_per_ramp, rest, shared)
                          if rest else []))
        return [coned.get(ch) or solved[ch] for ch in variants]
    if geom.preloaded:
        return _preloaded_variants(geom, mesh, steps_per_ramp, variants, shared)
    t0 = time.perf_counter()
    frac = torque_fractions(steps_per_ramp)
    base = None
    try:
        base = LostMotionModel(geom, mesh, shared=shared)
        mounted = mount_wave_generator(base)
    except Exception as exc:
        failed = failed_result(exc, base, t0)
        return [failed for _ in variants]
    out, solved = [], {}
    for ch in variants:
        t1 = time.perf_counter()
        model = None
        try:
            if ch.fe_part() not in solved:
                model = base.fork()
                model.apply_tooth_stage_changes(ch.fe_part())
                solved[ch.fe_part()] = (model, _torque_test(model, frac, mounted, None))
            model, test = solved[ch.fe_part()]
            out.append(lost_motion_result(model, ch, frac, mounted, test, t1))
        except Exception as exc:
            out.append(failed_result(exc, model, t1))
    return out


def _coned(geom: DriveGeometry, mesh: DriveMesh, steps_per_ramp: int, changes: ModelChanges,
           zone_deg: float | None = None, keep_fields: bool = False) -> LostMotionResult:
    # imported here: hdwf.fe.coning builds on this module's mount and test
    from hdwf.fe.coning import coned_lost_motion
    return coned_lost_motion(geom, mesh, steps_per_ramp, changes, zone_deg, keep_fields)


def _preloaded_variants(geom: DriveGeometry, mesh: DriveMesh, steps_per_ramp: int,
                        variants: list[ModelChanges], shared: SharedBodies | None) -> list[LostMotionResult]:
    """Preloaded teeth are in from the mount on and the CS support changes the preload: each
    variant that changes the section mounts its own wave generator, except that friction acts
    only from the assembled state on (``preload.mount_with_cutback``), so variants that differ
    in their flank friction only share one frictionless mount; series elements share it all."""
    frac = torque_fractions(steps_per_ramp)
    out, solved, mounts = [], {}, {}
    for ch in variants:
        t1 = time.perf_counter()
        key = ch.fe_part()
        if key not in solved:
            plain = replace(key, flank_friction=0.0)
            if plain not in mounts:
                mounts[plain] = _preloaded_mount(geom, mesh, plain, shared)
            model, mounted, exc = mounts[plain]
            if exc is None:
                try:
                    model = with_flank_friction(model, mounted.solution, key)
                    test = _torque_test(model, frac, mounted, None)
                except Exception as err:   # any failure is reported, never a silent number
                    exc = err
            solved[key] = (model, mounted, test if exc is None else None, exc)
        model, mounted, test, exc = solved[key]
        out.append(failed_result(exc, model, t1) if exc is not None
                   else lost_motion_result(model, ch, frac, mounted, test, t1))
    return out


def _preloaded_mount(geom: DriveGeometry, mesh: DriveMesh, changes: ModelChanges, shared: SharedBodies | None):
    """A model of ``changes`` (frictionless) with its wave generator mounted and teeth ramped in:
    (model, mounted, None), or (model or None, None, the exception) if that failed."""
    model = None
    try:
        model = LostMotionModel(geom, mesh, changes=changes, zone_deg=_zone(geom, None), shared=shared)
        return model, mount_wave_generator(model, True), None
    except Exception as exc:   # reported by every variant that needs this mount
        return model, None, exc
