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
T = (1/N) sum_j T'_j(theta), T'_j the full section's torque-twist relation at push k_j.

Why combining curves is exact for our Phi.  ``cycle`` defines Phi = theta(+T) - theta(-T)
(the twists at +-T minus the first state's, which cancels).  Frictionless contact is
elastic and path independent: the state at a torque does not depend on the levels before
it (up to the re-linearisation of the tooth rows at a state, ``relinearise.redetect_teeth``).
So theta(+-T) of the slices in parallel is found from each slice's twist-torque relation
alone: sample it, invert the summed monotone relation mean_j T'_j(theta) = +-T, then solve
every slice at its share T'_j* and insert that point (``refine``) until every slice's
twist equals the common theta to ``THETA_TOL``; at that point the combination is the
coupled solution of N sections sharing one rotation, not an interpolation.

What it neglects.  The slices exchange no shear (a continuous cup couples neighbouring
sections; a plane-stress section at each z is the classic multi-section / "quasi-3D"
approximation), the cup's torsion between the slices and the output (every slice's rim is
tied to the same rotation), the bearing's own tilt and edge loading, and friction (with
friction Phi is path dependent and the combination would not hold).  The tooth profile and
relief are the same in every slice (no profile modification along the face).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from hdwf.drive.cam import cam_for_push
from hdwf.drive.geometry import ARCMIN, DriveGeometry
from hdwf.drive.mesh import DriveMesh
from hdwf.fe.changes import ModelChanges
from hdwf.fe.cycle import ZERO_TORQUE_BIAS, mount_wave_generator
from hdwf.fe.model import LostMotionModel
from hdwf.fe.preload import PRELOAD_ZONE_DEG
from hdwf.fe.relinearise import redetect_teeth
from hdwf.fe.solver import ContactFailure

# torques first sampled on each slice's curve, as multiples of the test torque (each side);
# a slice that has to carry more is sampled further out (twice its largest) when needed
SAMPLE_FRACTIONS = (ZERO_TORQUE_BIAS, 0.25, 0.5, 1.0, 2.0)
THETA_TOL = 5e-3 * ARCMIN   # rad: slice twists at the combined solution agree to this (about 3x
                            # the contact tolerance: 0.01 um over r_b ~ 20 mm is 1.7e-3 arcmin)
MAX_REFINE = 12             # refinement rounds per torque


def slice_pushes(coning: float, n_slices: int) -> np.ndarray:
    """k_j = 1 + c zeta_j at the slice centres zeta_j = (j + 1/2) / N."""
    zeta = (np.arange(n_slices) + 0.5) / n_slices
    return 1.0 + coning * zeta


def coned_geometry(geom: DriveGeometry, push: float) -> DriveGeometry:
    """``geom`` with the cam re-sized to push the nominal bearing out by ``push`` times the
    design's own push (``deflection_coeff`` w0; k = 1: the same cam)."""
    A, B = cam_for_push(geom.d_nom, geom.Gr_nom, push * (geom.deflection_coeff * geom.w0), geom.cam_n)
    return replace(geom, cam_A=A, cam_B=B)


@dataclass
class SliceCurve:
    """One slice (push k): its mounted model on each side and the sampled (T', theta) points."""
    push: float
    models: dict = field(default_factory=dict)     # side (+1/-1) -> [model, active]
    torque: list = field(default_factory=list)     # T' (N mm), full-section torque
    twist: list = field(default_factory=list)      # theta (rad), absolute rim twist
    levels: int = 0

    def solve(self, torque: float) -> float:
        """Solve the slice at full-section torque ``torque`` (N mm), record and return theta."""
        side = 1 if torque > 0 else -1
        model, active = self.models[side]
        level = model.solve_level(torque, active)
        level, _ = redetect_teeth(model, torque, level)
        self.models[side][1] = level.active
        self.torque.append(float(torque))
        self.twist.append(float(level.twist))
        self.levels += 1
        return float(level.twist)

    def relation(self, side: int) -> tuple[np.ndarray, np.ndarray]:
        """The relation sampled on ``side`` (+1: T' > 0, -1: T' < 0) sorted by torque:
        (theta, T'); raises if not monotone.

        One side only: the two sides are reached on separate paths from the mount, and a
        locked slice's states at +bias and -bias can cross by a few contact tolerances
        (twist(-bias) > twist(+bias)), which is not a property of either side's relation.
        Between the sides the slice sits in its backlash and carries (about) the bias."""
        T, th = np.array(self.torque), np.array(self.twist)
        keep = np.sign(T) == side
        order = np.argsort(T[keep])
        T, th = T[keep][order], th[keep][order]
        drop = -np.diff(th).min(initial=0.0)
        if drop > THETA_TOL:
            raise ContactFailure(f"coning: slice k={self.push:.4f} twist not monotone in torque "
                                 f"on the {'+' if side > 0 else '-'} side (falls by "
                                 f"{drop / ARCMIN:.2e} arcmin)")
        return np.maximum.accumulate(th), T


def build_slice(base: LostMotionModel, geom: DriveGeometry, push: float) -> SliceCurve:
    """Mount the wave generator of push ``push`` on a fork of ``base`` (shared factorisation)
    with the teeth ramped in, free the FS rotation and sample the curve on both sides."""
    model = base.fork()
    model.geometry = coned_geometry(base.geometry, push)    # (with the base's flank layer)
    mounted = mount_wave_generator(model, True)
    model.mode_list = model.mode_list + [("fs", "rot")]
    curve = SliceCurve(push)
    for side in (1, -1):
        m = model.fork()
        curve.models[side] = [m, mounted.solution.active]
        # as in ``cycle``: the bias first (not kept: a lightly preloaded FS can sit at the
        # mount in a detent of two near-radial tip contacts that a small torque does not
        # leave, a state the loaded branch never returns to), then up the loaded branch and
        # back to the bias, the edge of the backlash on that side
        level = m.solve_level(side * ZERO_TORQUE_BIAS * geom.torque, mounted.solution.active)
        curve.models[side][1] = level.active
        for f in SAMPLE_FRACTIONS[1:] + SAMPLE_FRACTIONS[:1]:
            curve.solve(side * f * geom.torque)
    return curve


def _combined_theta(curves: list[SliceCurve], torque: float) -> tuple[float, np.ndarray]:
    """theta with mean_j T'_j(theta) = torque on the piecewise-linear sampled relations, and
    each slice's share T'_j there."""
    rel = [c.relation(1 if torque > 0 else -1) for c in curves]
    grid = np.unique(np.concatenate([th for th, _ in rel]))
    total = np.mean([np.interp(grid, th, T) for th, T in rel], axis=0)
    if not (total[0] <= torque <= total[-1]):
        raise ContactFailure(f"coning: torque {torque:.4g} N mm outside the sampled range")
    total = np.maximum.accumulate(total)
    # the first grid point where the summed relation reaches the torque (flat parts: any)
    k = int(np.searchsorted(total, torque))
    if k == 0:
        theta = grid[0]
    else:
        a, b = total[k - 1], total[k]
        theta = grid[k] if b == a else grid[k - 1] + (torque - a) / (b - a) * (grid[k] - grid[k - 1])
    shares = np.array([np.interp(theta, th, T) for th, T in rel])
    return float(theta), shares


def coupled_twist(curves: list[SliceCurve], torque: float) -> tuple[float, int]:
    """The common twist of the slices in parallel at ``torque`` (N mm), refined until each
    slice solved at its share has that twist to ``THETA_TOL``; returns (theta, rounds).

    A slice whose sampled relation ends before the combined twist is first sampled further
    out (twice its largest torque on that side); a slice whose share lies within its
    zero-torque band (|T'_j| <= the bias) sits in its backlash and is not solved."""
    sign, worst = (1.0 if torque > 0 else -1.0), math.inf
    for rounds in range(MAX_REFINE):
        theta, shares = _combined_theta(curves, torque)
        short = [c for c in curves if sign * (theta - c.relation(int(sign))[0][-1 if sign > 0 else 0]) > 0]
        for c in short:
            c.solve(2.0 * (max(c.torque) if sign > 0 else min(c.torque)))
        if short:
            continue
        worst = 0.0
        for c, Tj in zip(curves, shares):
            if abs(Tj) <= ZERO_TORQUE_BIAS * abs(torque) * (1 + 1e-6):
                continue
            worst = max(worst, abs(c.solve(Tj) - theta))
        if worst < THETA_TOL:
            return theta, rounds
    raise ContactFailure(f"coning: slice twists differ by up to {worst / ARCMIN:.2e} arcmin from "
                         f"the combined twist after {MAX_REFINE} refinements")


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
    rounds: int


def combine(curves: dict, coning: float, n_slices: int, test_torque: float) -> ConedResult:
    """Phi of ``n_slices`` slices at coning slope ``coning`` from the slice curves (keyed by
    rounded push; refined in place)."""
    ks = slice_pushes(coning, n_slices)
    sl = [curves[round(float(k), 9)] for k in ks]
    try:
        tp, rp = coupled_twist(sl, test_torque)
        tm, rm = coupled_twist(sl, -test_torque)
    except ContactFailure as exc:
        return ConedResult(math.nan, math.nan, math.nan, "failed", f"ContactFailure: {exc}",
                           tuple(ks), sum(c.levels for c in sl), 0)
    # the first state (+bias) cancels in Phi = theta(+T) - theta(-T)
    return ConedResult((tp - tm) / ARCMIN, tp / ARCMIN, -tm / ARCMIN, "ok", "", tuple(ks),
                       sum(c.levels for c in sl), rp + rm)


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
        carries their part already (``ModelChanges.geometry_part``).

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
    curves, failed = {}, {}
    for c, n in cases:
        for k in slice_pushes(c, n):
            key = round(float(k), 9)
            if key in curves or key in failed:
                continue
            try:
                curves[key] = build_slice(base, geom, key)
            except Exception as exc:
                failed[key] = f"{type(exc).__name__}: {exc} (slice push {key:.4f})"
    out = []
    for c, n in cases:
        keys = [round(float(k), 9) for k in slice_pushes(c, n)]
        bad = [failed[k] for k in keys if k in failed]
        if bad:
            out.append(ConedResult(math.nan, math.nan, math.nan, "failed", bad[0], tuple(keys), 0, 0))
        else:
            out.append(combine(curves, c, n, geom.torque))
    return out
