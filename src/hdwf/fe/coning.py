"""Coning (quasi-3D prototype): the section solved at N slices along the face width, in parallel.

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

What it neglects.  The slices exchange no shear (a continuous cup couples neighbouring
sections; a plane-stress section at each z is the classic multi-section / "quasi-3D"
approximation), the cup's torsion between the slices and the output (every slice's rim is
tied to the same rotation), the bearing's own tilt and edge loading, and friction (with
friction a state depends on its path; a prescribed twist is solved frictionless only).  The tooth profile and
relief are the same in every slice (no profile modification along the face).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from hdwf.drive.cam import cam_for_push
from hdwf.drive.geometry import ARCMIN, DriveGeometry
from hdwf.drive.mesh import DriveMesh
from hdwf.fe.changes import ModelChanges
from hdwf.fe.cycle import mount_wave_generator
from hdwf.fe.model import LostMotionModel
from hdwf.fe.preload import PRELOAD_ZONE_DEG
from hdwf.fe.relinearise import GEO_MAX_IT, GEO_TOL, settle
from hdwf.fe.solver import ContactFailure, Twist

THETA_TOL = 1e-3 * ARCMIN   # rad: the twist at +-T to this (0.3 % of a 0.3 arcmin Phi)
MAX_EVALUATIONS = 40        # twists tried per torque
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
    active: dict = field(default_factory=dict)       # side (+1/-1) -> warm-start active set
    torques: dict = field(default_factory=dict)      # twist (rad) -> T'
    levels: int = 0

    def torque_at(self, theta: float) -> float:
        """T' at rim twist ``theta`` (rad): solved on a fork of the mount and settled."""
        if theta in self.torques:
            return self.torques[theta]
        side = 1 if theta >= 0 else -1
        at = self.model.fork()
        level = at.solve_level(Twist(theta), self.active[side])
        level, err, ok = settle(at, level, Twist(theta), GEO_TOL)
        if not ok:
            raise ContactFailure(f"coning: slice k={self.push:.4f} at {theta / ARCMIN:.4g} arcmin: "
                                 f"tooth gaps {err * 1000:.3f} um off their linearisation after "
                                 f"{GEO_MAX_IT} re-linearisations")
        self.active[side] = level.active
        self.levels += 1
        self.torques[theta] = level.torque
        return level.torque


def build_slice(base: LostMotionModel, push: float) -> Slice:
    """Mount the wave generator of push ``push`` on a fork of ``base`` (shared factorisation)
    with the teeth ramped in, and free the FS rotation."""
    model = base.fork()
    model.geometry = coned_geometry(base.geometry, push)    # (with the base's flank layer)
    mounted = mount_wave_generator(model, True)
    model.mode_list = model.mode_list + [("fs", "rot")]
    return Slice(push, model, {1: mounted.solution.active, -1: mounted.solution.active})


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
        base = LostMotionModel(geom, mesh, zone_deg=zone_deg, changes=changes)
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
