"""Coning (quasi-3D): the section solved at N slices along the face width, in parallel.

What it models.  A flexspline cup is held circular by its diaphragm, so the radial
deflection the wave generator imposes grows (to first order linearly) with the distance z
from the diaphragm: the tooth ring is a cone, not a cylinder.  Across the face width b the
push at the major axis is w(zeta) = w0 (1 + c zeta), zeta = 0 at the diaphragm end of the
teeth and 1 at the open end, c = b / z_0 (z_0: diaphragm to the inner end of the face) the
coning slope (dimensionless; 0 is today's uniform section).  The design push w0 = m sits at
the diaphragm end because the tooth profile has to clear the exit zone at every section,
and ours (the relief derived at w0 = m, ``hdwf.drive.relief``) clears only for w >= m: a
smaller push withdraws the FS tooth less while it advances as much, and on the rack path the
relief needed grows to 1.6 times (w = 0.95 m) and to no finite multiple (w <= 0.9 m, the
crossing starts deeper than the relief), so a slice below m locks on its crossing tips.
Each slice j (zeta_j = (j + 1/2) / N) is today's 2D section with the cam re-sized to push
k_j w0, k_j = 1 + c zeta_j (the cam of Eq. 3 with A + B = d_nom/2 + k_j w0 + G_r,nom/2
and the same perimeter; nothing else changes, so all slices of a design share one mesh and
one factorisation).

Slices in parallel.  Every slice carries b/N of the face width; in plane stress every
stiffness of the section scales with its thickness, so a slice at torque T_j behaves as the
full section at N T_j (the ball springs are scaled with it: the bearing is smeared over the
face width).  All slices share the FS output rotation theta and the torques add:
T(theta) = (1/N) sum_j T'_j(theta), T'_j the full section's torque at twist theta and push k_j.

Displacement control.  Each slice is solved at a prescribed rim twist (``solver.Twist``: the
torque is the unknown), so at a given theta the slices are independent, and a preloaded slice
that would snap between two equilibria under a torque has one state at a twist.  Every state
is solved on a fork of the slice's mount (the same starting rows) and its tooth and cam rows
settled to the true gap at that state (``relinearise.settle``), as the main test settles its
states at +-T: the torque at a twist does not depend on the twists solved before it.  The
twist at +-T is found on the path from the mount, theta growing in the torque's direction:
steps until T(theta) passes the torque, then regula falsi (Illinois) to ``THETA_TOL``;
Phi = theta(+T) - theta(-T).

In the model.  ``ModelChanges.coning_slope`` c (with ``coning_slices`` N) routes
``solve_lost_motion`` here (``coned_lost_motion``): every level of the test's path is the twist
at that torque (frictionless, a state does not depend on its path), the zero-torque levels at
``cycle.ZERO_TORQUE_BIAS`` T towards the last load as in the section's test; series elements
act on the twist as there.  The effect ``coning`` (``hdwf.validation.effects``) offers it to a
campaign.

What it neglects.  The slices exchange no shear (a continuous cup couples neighbouring
sections; a plane-stress section at each z is the classic multi-section / "quasi-3D"
approximation), the cup's torsion between the slices and the output (every slice's rim is
tied to the same rotation), the bearing's own tilt and edge loading, and friction (with
friction a state depends on its path; a prescribed twist is solved frictionless only).  The tooth profile and
relief are the same in every slice (no profile modification along the face).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from hdwf.drive.cam import cam_for_push
from hdwf.drive.geometry import ARCMIN, DriveGeometry
from hdwf.drive.mesh import DriveMesh
from hdwf.fe.changes import ModelChanges
from hdwf.fe.cycle import (ZERO_TORQUE_BIAS, LostMotionResult, MountedWaveGenerator, TorqueTest, failed_result,
                           lost_motion_result, mount_wave_generator, teeth_in_contact, torque_fractions)
from hdwf.fe.model import LostMotionModel
from hdwf.fe.preload import PRELOAD_ZONE_DEG
from hdwf.fe.relinearise import GEO_MAX_IT, GEO_TOL, settle
from hdwf.fe.solver import ContactFailure, Twist

THETA_TOL = 1e-3 * ARCMIN   # rad: the twist at +-T to this (0.3 % of a 0.3 arcmin Phi)
MAX_EVALUATIONS = 40        # twists tried per torque
# active-set iterations of a slice state: a slice pushed beyond the design push presses more
# teeth in, and a re-linearisation at a twist then moves a few hundred pairs across zero, added a
# few at a time (``solver``): HD 120 slices at 1.1-1.2 w0 on a 0.186 m preload needed more than 200
SLICE_MAX_ITER = 1000
FIRST_STEP = 0.02 * ARCMIN  # rad: the first twist tried (a tenth of a preloaded HD 42's Phi/2;
                            # the secant steps grow it at most 4 times a step)


def slice_pushes(coning: float, n_slices: int) -> np.ndarray:
    """k_j = 1 + c zeta_j at the slice centres zeta_j = (j + 1/2) / N."""
    zeta = (np.arange(n_slices) + 0.5) / n_slices
    return 1.0 + coning * zeta


def coned_geometry(geom: DriveGeometry, push: float) -> DriveGeometry:
    """``geom`` with the cam re-sized to push the nominal bearing out by ``push`` times the
    design's own push (``deflection_coeff`` w0; k = 1: the same cam)."""
    A, B = cam_for_push(geom.d_nom, geom.Gr_nom, push * (geom.deflection_coeff * geom.w0), geom.cam_n)
    return replace(geom, cam_A=A, cam_B=B)


def twist_at_torque(torque_at: Callable[[float], float], target: float, first_step: float,
                    tol: float = THETA_TOL, max_evaluations: int = MAX_EVALUATIONS) -> tuple[float, int]:
    """The first twist on the path from 0 (growing in the sign of ``target``) where the
    torque-twist relation ``torque_at`` reaches ``target``; returns (theta, evaluations).

    Steps out from 0 (the first ``first_step``, then the secant's extrapolation, at least 1.5
    and at most 4 times the last twist) until the torque passes the target, then regula
    falsi with the Illinois rule until the bracket is narrower than ``tol``.  Raises
    ``ContactFailure`` if ``max_evaluations`` do not reach that."""
    sign = math.copysign(1.0, target)
    lo, t_lo = 0.0, torque_at(0.0)
    hi, count = sign * abs(first_step), 1
    while True:
        t_hi = torque_at(hi)
        count += 1
        if sign * (t_hi - target) >= 0:
            break
        if count >= max_evaluations:
            raise ContactFailure(f"coning: torque {target:.4g} N mm not reached by twist "
                                 f"{hi / ARCMIN:.4g} arcmin")
        slope = (t_hi - t_lo) / (hi - lo)
        guess = hi + (target - t_hi) / slope if sign * slope > 0 else 4 * hi
        lo, t_lo, hi = hi, t_hi, sign * min(max(sign * guess, 1.5 * abs(hi)), 4 * abs(hi))
    side = 0      # Illinois: halve the weight of an end kept twice
    while abs(hi - lo) > tol:
        if count >= max_evaluations:
            raise ContactFailure(f"coning: twist at torque {target:.4g} N mm not within "
                                 f"{tol / ARCMIN:.1e} arcmin after {count} evaluations")
        theta = lo + (target - t_lo) * (hi - lo) / (t_hi - t_lo)
        theta = min(max(theta, min(lo, hi) + 0.1 * tol), max(lo, hi) - 0.1 * tol)
        t = torque_at(theta)
        count += 1
        if sign * (t - target) >= 0:
            hi, t_hi = theta, t
            if side == -1:
                t_lo = target + 0.5 * (t_lo - target)
            side = -1
        else:
            lo, t_lo = theta, t
            if side == 1:
                t_hi = target + 0.5 * (t_hi - target)
            side = 1
    return lo + (target - t_lo) * (hi - lo) / (t_hi - t_lo), count


@dataclass
class Slice:
    """One slice (push k): its mounted model, FS rotation free, and the torques it has needed
    at the twists asked (full-section torque T', N mm)."""
    push: float
    model: LostMotionModel
    mounted: MountedWaveGenerator
    active: dict = field(default_factory=dict)       # side (+1/-1) -> warm-start active set
    torques: dict = field(default_factory=dict)      # twist (rad) -> T'
    levels: int = 0
    state_iterations: int = 0                        # active-set iterations of the states solved

    def torque_at(self, theta: float) -> float:
        """T' at rim twist ``theta`` (rad): solved on a fork of the mount and settled."""
        if theta in self.torques:
            return self.torques[theta]
        return self.state_at(theta)[1].torque

    def state_at(self, theta: float):
        """(the fork it was solved on, the settled level) at rim twist ``theta`` (rad), reached
        from the mount's zero twist in up to two halvings if the active set does not converge."""
        side = 1 if theta >= 0 else -1
        at = self.model.fork()
        try:
            level = at.solve_level_stepped(Twist(theta), self.active[side], Twist(0.0))
            level, err, ok = settle(at, level, Twist(theta), GEO_TOL)
        except ContactFailure as exc:
            raise ContactFailure(f"coning: slice k={self.push:.4f}: {exc}") from exc
        if not ok:
            raise ContactFailure(f"coning: slice k={self.push:.4f} at {theta / ARCMIN:.4g} arcmin: "
                                 f"tooth gaps {err * 1000:.3f} um off their linearisation after "
                                 f"{GEO_MAX_IT} re-linearisations")
        self.active[side] = level.active
        self.levels += 1
        self.state_iterations += at.iterations - self.model.iterations
        self.torques[theta] = level.torque
        return at, level


def build_slice(base: LostMotionModel, push: float) -> Slice:
    """Mount the wave generator of push ``push`` on a fork of ``base`` (shared factorisation)
    with the teeth ramped in, and free the FS rotation."""
    model = base.fork()
    model.geometry = coned_geometry(base.geometry, push)    # (with the base's flank layer)
    mounted = mount_wave_generator(model, True)
    model.mode_list = model.mode_list + [("fs", "rot")]
    return Slice(push, model, mounted, {1: mounted.solution.active, -1: mounted.solution.active})


@dataclass
class ConedResult:
    """Phi of the coned cup: status, the twists, and how it was solved."""
    lost_motion_arcmin: float
    phi_plus_arcmin: float
    phi_minus_arcmin: float
    status: str
    reason: str
    pushes: tuple
    levels: int
    evaluations: int


def combine(slices: list[Slice], test_torque: float) -> ConedResult:
    """Phi of the slices in parallel: the common twists at +-``test_torque`` (N mm)."""
    pushes = tuple(s.push for s in slices)

    def torque_at(theta: float) -> float:
        return float(np.mean([s.torque_at(theta) for s in slices]))

    try:
        tp, ep = twist_at_torque(torque_at, test_torque, FIRST_STEP)
        tm, em = twist_at_torque(torque_at, -test_torque, FIRST_STEP)
    except (ContactFailure, ValueError) as exc:
        return ConedResult(math.nan, math.nan, math.nan, "failed", f"{type(exc).__name__}: {exc}",
                           pushes, sum(s.levels for s in slices), 0)
    return ConedResult((tp - tm) / ARCMIN, tp / ARCMIN, -tm / ARCMIN, "ok", "", pushes,
                       sum(s.levels for s in slices), ep + em)


def solve_coned(geom: DriveGeometry, mesh: DriveMesh, cases: list[tuple[float, int]],
                zone_deg: float = PRELOAD_ZONE_DEG,
                changes: ModelChanges | None = None) -> list[ConedResult]:
    """Phi of one design for several (coning slope c, slice count N), sharing the mesh, the
    factorisation and every slice whose push two cases have in common.

    Parameters
    ----------
    geom : DriveGeometry
        The design (its ``interference_m`` and ``tip_relief`` as for ``solve_lost_motion``).
    mesh : DriveMesh
        Its mesh.
    cases : list of (float, int)
        (c, N) pairs.
    zone_deg : float
        Half width of the watched tooth zones (every tooth by default).
    changes : ModelChanges, optional
        Effects of the model (e.g. the flank layer), as for ``solve_lost_motion``; the geometry
        carries their part already (``ModelChanges.geometry_part``).  Frictionless only.

    Returns
    -------
    list of ConedResult
        One per case; a failed slice fails every case that uses it (status "failed", no number).
    """
    try:
        base = LostMotionModel(geom, mesh, zone_deg=zone_deg, changes=changes, max_iter=SLICE_MAX_ITER)
    except Exception as exc:   # any failure is reported, never a silent number
        return [ConedResult(math.nan, math.nan, math.nan, "failed", f"{type(exc).__name__}: {exc}",
                            (), 0, 0) for _ in cases]
    slices, failed = {}, {}
    for c, n in cases:
        for k in slice_pushes(c, n):
            key = round(float(k), 9)
            if key in slices or key in failed:
                continue
            try:
                slices[key] = build_slice(base, key)
            except Exception as exc:
                failed[key] = f"{type(exc).__name__}: {exc} (slice push {key:.4f})"
    out = []
    for c, n in cases:
        keys = [round(float(k), 9) for k in slice_pushes(c, n)]
        bad = [failed[k] for k in keys if k in failed]
        if bad:
            out.append(ConedResult(math.nan, math.nan, math.nan, "failed", bad[0], tuple(keys), 0, 0))
        else:
            out.append(combine([slices[k] for k in keys], geom.torque))
    return out


def coned_lost_motion(geom: DriveGeometry, mesh: DriveMesh, steps_per_ramp: int,
                      changes: ModelChanges, zone_deg: float | None = None,
                      keep_fields: bool = False) -> LostMotionResult:
    """The lost-motion test of the coned cup (``changes.coning_slope`` c, ``coning_slices`` N):
    the section's result (``cycle.LostMotionResult``) with the slices in parallel.

    Every level of 0 -> +T -> 0 -> -T -> 0 is the common twist at which the slices' torques
    add up to that level's torque (``twist_at_torque``).  The record of the mount (the wave
    generator's push, the most loaded ball) is the open-end slice's, the most pushed; the teeth in
    contact, their loaded arc and the tooth penetration are the largest over the slices at +T,
    each slice solved again at the twist found; ``keep_fields`` keeps the open-end slice's
    displacements (``wg``, ``plus``).  Frictionless only.  Any failure gives status "failed" and
    no number.
    """
    t0 = time.perf_counter()
    frac = torque_fractions(steps_per_ramp)
    last = None
    try:
        if changes.flank_friction > 0:
            raise ValueError("coning is solved at prescribed twists, frictionless only "
                             f"(flank_friction = {changes.flank_friction})")
        if changes.coning_slices < 1:
            raise ValueError(f"coning_slices must be at least 1, not {changes.coning_slices}")
        section = replace(changes, coning_slope=0.0, coning_slices=1)
        base = LostMotionModel(geom, mesh, changes=section, max_iter=SLICE_MAX_ITER,
                               zone_deg=PRELOAD_ZONE_DEG if zone_deg is None else zone_deg)
        slices = [build_slice(base, float(k))
                  for k in slice_pushes(changes.coning_slope, changes.coning_slices)]
        last = slices[-1]

        def torque_at(theta: float) -> float:
            return float(np.mean([s.torque_at(theta) for s in slices]))

        twists, found, sign = [], {}, 1.0
        for fraction in frac:
            if abs(fraction) > 1e-12:
                sign = math.copysign(1.0, fraction)
                target = fraction * geom.torque
            else:
                target = ZERO_TORQUE_BIAS * geom.torque * sign
            if target not in found:
                found[target] = twist_at_torque(torque_at, target, FIRST_STEP)[0]
            twists.append(found[target])
        test = _plus_record(slices, found[geom.torque], np.array(twists), keep_fields)
        res = lost_motion_result(last.model, changes, frac, last.mounted, test, t0)
    except Exception as exc:   # any failure is reported, never a silent number
        return failed_result(exc, last.model if last is not None else None, t0)
    levels = sum(s.levels for s in slices)
    return replace(res, iterations=sum(s.model.iterations + s.state_iterations for s in slices),
                   notes=res.notes + f"; coned cup: slope {changes.coning_slope:g}, "
                   f"{changes.coning_slices} slices (pushes {slices[0].push:.4f}-{last.push:.4f} w0), "
                   f"{levels} slice states solved")


def _plus_record(slices: list[Slice], theta_plus: float, twists: np.ndarray, keep_fields: bool) -> TorqueTest:
    """The checks of the test at +T: every slice solved at the twist found there. The slices keep
    their settled gaps; the tooth pairs are not re-found from scratch, so that check is NaN (not
    made), never a number that reads as passed."""
    teeth, arc, pen, fields = 0, float("nan"), 0.0, None
    for s in slices:
        at, level = s.state_at(theta_plus)
        kinds = np.array([i[0] for i in level.pair_ids])
        count, a = teeth_in_contact(at, level, kinds)
        teeth = max(teeth, count)
        arc = a if math.isnan(arc) else max(arc, a)
        pen = max(pen, float(-(level.gap[kinds != "ball"]).min(initial=0.0)))
        if keep_fields and s is slices[-1]:
            fields = {"wg": s.model.full_displacements(s.mounted.solution, 0.0),
                      "plus": at.full_displacements(level, level.torque)}
    return TorqueTest(twists, pen, float("nan"), teeth, arc, fields)
