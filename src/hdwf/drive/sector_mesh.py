"""The toothed rings (FS, CS) meshed as one tooth period and copied round.

Every tooth of a design is the same (the design variables move all flanks alike), so the FS
and CS are meshed by gmsh as one period, the sector [0, 2 pi / z] from the middle of one
tooth (FS) or space (CS) to the middle of the next, whose two radial cuts are gmsh-periodic
under the rotation by 2 pi / z, with the element size growing linearly in radius across the
rim (sizes extended from the boundary of so narrow a sector grade the rim unlike a whole
ring's); the period is then rotated round in numpy, each copy's first cut merged with the
previous copy's second.  Tip corners may be rounded (``RingProfile.tip_round``): a circular arc
tangent to the flank's chord near the tip and to the tip circle, meshed with its own
segments and the size graded down to theirs around it.  That meshes a ring in a hundredth of
the time gmsh takes for the whole outline, and every tooth gets the same nodes.  The half
model takes z / 2 copies (its cuts at 0 and pi are then exact images under the rotation
by pi), the full model z, the last copy closed onto the first.  Hand-written: only the
period's outline (as ``hdwf.drive.mesh`` draws a whole ring) and the copying.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import gmsh
import numpy as np

from hdwf.drive.gmsh_read import read_surface


@dataclass(frozen=True)
class RingProfile:
    """One toothed ring's period: the flank radii ``rr`` (from the land to the middle feature
    at angle 0, a FS tooth tip or a CS space root) and their half angles, and the plain
    circle that closes the ring (FS bore, CS outer rim)."""
    z: int
    rr: np.ndarray
    half_angle: np.ndarray
    r_plain: float
    outline_group: str          # e.g. "fs_teeth"
    plain_group: str            # e.g. "fs_bore"
    tip_round: float = 0.0      # radius (mm) of the tip corners' rounding, 0 = sharp
    tip_at_middle: bool = True  # the tips are the middle feature (FS) or the land (CS)


@dataclass(frozen=True)
class RingSizes:
    """Element sizes of a period: ``tooth`` at the outline, ``plain`` on the closing circle
    (uniform there), ``n_flank`` segments on every flank, ``round_segments`` on every tip
    round (if the profile has one)."""
    tooth: float
    plain: float
    n_flank: int
    round_segments: int = 2


@dataclass
class SectorMesh:
    """One period as gmsh meshed it: nodes (2, n), triangles (3, k), the named edges
    (sector node ids) and the nodes of the cuts at angle 0 and 2 pi / z, paired."""
    p: np.ndarray
    t: np.ndarray
    edges: dict[str, np.ndarray]
    cut0: np.ndarray
    cut1: np.ndarray


def _rotation(angle: float) -> np.ndarray:
    return np.array([[math.cos(angle), -math.sin(angle), 0.0, 0.0],
                     [math.sin(angle), math.cos(angle), 0.0, 0.0],
                     [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def mesh_period(prof: RingProfile, sizes: RingSizes, algorithm: int, lc_precision: float) -> SectorMesh:
    """Mesh one period in a gmsh model of its own (gmsh must be initialised)."""
    alpha = 2.0 * math.pi / prof.z
    gmsh.model.add(f"period_{prof.outline_group}")
    geo = gmsh.model.geo
    c = geo.addPoint(0.0, 0.0, 0.0, 1.0)

    def point(r, th, size):
        return geo.addPoint(r * math.cos(th), r * math.sin(th), 0.0, size)

    rc = float(prof.rr[-1])
    p0, p1 = point(rc, 0.0, sizes.tooth), point(rc, alpha, sizes.tooth)
    outline, flanks, rounds = _tooth_outline(geo, prof, sizes, c, p0, p1)
    q0, q1 = point(prof.r_plain, 0.0, sizes.plain), point(prof.r_plain, alpha, sizes.plain)
    plain = geo.addCircleArc(q1, c, q0)
    cut0, cut1 = geo.addLine(q0, p0), geo.addLine(q1, p1)
    surf = geo.addPlaneSurface([geo.addCurveLoop(outline + [-cut1, plain, cut0])])
    geo.synchronize()
    gmsh.model.mesh.setPeriodic(1, [cut1], [cut0], list(_rotation(alpha).ravel()))
    for cv in flanks:
        gmsh.model.mesh.setTransfiniteCurve(cv, sizes.n_flank + 1)
    for cv in rounds:
        gmsh.model.mesh.setTransfiniteCurve(cv, sizes.round_segments + 1)
    gmsh.model.mesh.setTransfiniteCurve(plain, max(1, math.ceil(alpha * prof.r_plain / sizes.plain)) + 1)
    _rim_size_field(prof, sizes, rounds)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.Algorithm", algorithm)
    gmsh.option.setNumber("Mesh.LcIntegrationPrecision", lc_precision)
    gmsh.model.mesh.generate(2)
    period = read_surface(surf)
    p, edges_of = period.points, period.curve_edges
    edges = {prof.outline_group: edges_of(outline), prof.plain_group: edges_of([plain])}
    return SectorMesh(p, period.triangles, edges, _cut_nodes(p, edges_of([cut0])),
                      _cut_nodes(p, edges_of([cut1])))


def _tooth_outline(geo, prof: RingProfile, sizes: RingSizes, c: int, p0: int, p1: int):
    """The period's toothed outline from ``p0`` (angle 0) to ``p1`` (angle 2 pi / z): the two
    flank splines, the land arc between them and the arcs of the middle feature, with the tip
    corners rounded if ``prof.tip_round`` > 0.  Returns (outline curves in order, the two
    flank splines, the round arcs)."""
    alpha = 2.0 * math.pi / prof.z
    rr, ha = prof.rr, prof.half_angle
    right = [(r * math.cos(th), r * math.sin(th)) for r, th in zip(rr[::-1], ha[::-1])]  # middle -> land
    left = [(r * math.cos(alpha - th), r * math.sin(alpha - th)) for r, th in zip(rr, ha)]  # land -> middle
    rho = prof.tip_round
    if rho > 0.0 and prof.tip_at_middle:     # FS: the tips are the middle feature's corners
        right, (t_r, o_r) = _round_corner(right, rho, -1.0)
        left_rev, (t_l, o_l) = _round_corner(left[::-1], rho, +1.0)
        left = left_rev[::-1]
    elif rho > 0.0:                          # CS: the tips are the land's corners
        right_rev, (t_r, o_r) = _round_corner(right[::-1], rho, +1.0)
        right = right_rev[::-1]
        left, (t_l, o_l) = _round_corner(left, rho, -1.0)
    pr = [geo.addPoint(x, y, 0.0, sizes.tooth) for x, y in right]
    pl = [geo.addPoint(x, y, 0.0, sizes.tooth) for x, y in left]
    flanks = [geo.addSpline(pr), geo.addSpline(pl)]
    if rho <= 0.0:
        return ([geo.addCircleArc(p0, c, pr[0]), flanks[0], geo.addCircleArc(pr[-1], c, pl[0]),
                 flanks[1], geo.addCircleArc(pl[-1], c, p1)], flanks, [])
    q_r, q_l = geo.addPoint(*t_r, 0.0, sizes.tooth), geo.addPoint(*t_l, 0.0, sizes.tooth)
    c_r, c_l = geo.addPoint(*o_r, 0.0, 1.0), geo.addPoint(*o_l, 0.0, 1.0)
    if prof.tip_at_middle:
        rounds = [geo.addCircleArc(q_r, c_r, pr[0]), geo.addCircleArc(pl[-1], c_l, q_l)]
        outline = [geo.addCircleArc(p0, c, q_r), rounds[0], flanks[0], geo.addCircleArc(pr[-1], c, pl[0]),
                   flanks[1], rounds[1], geo.addCircleArc(q_l, c, p1)]
    else:
        rounds = [geo.addCircleArc(pr[-1], c_r, q_r), geo.addCircleArc(q_l, c_l, pl[0])]
        outline = [geo.addCircleArc(p0, c, pr[0]), flanks[0], rounds[0], geo.addCircleArc(q_r, c, q_l),
                   rounds[1], flanks[1], geo.addCircleArc(pl[-1], c, p1)]
    return outline, flanks, rounds


def round_corner_geometry(corner, toward_flank, land_sign: float, rho: float):
    """The round of radius ``rho`` (mm) of a tip corner: ``corner`` (x, y) on the tip circle,
    ``toward_flank`` a point of the flank beyond the round, the land running from the corner
    toward larger (``land_sign`` +1) or smaller (-1) polar angle.  The flank near the tip is
    taken as its chord to ``toward_flank``; the round touches that chord and the tip circle.
    Returns (tangent point on the flank, tangent point on the tip circle, centre, the tangent
    point's distance t from the corner along the flank: rho / tan(beta / 2), beta the
    corner's interior angle, were the land straight)."""
    C = np.asarray(corner, dtype=float)
    R = float(np.hypot(*C))
    along_land = np.array([-C[1], C[0]]) / R * land_sign
    chord = np.asarray(toward_flank, dtype=float) - C
    along_flank = chord / np.hypot(*chord)
    normal = along_land - (along_land @ along_flank) * along_flank     # off the flank, into the tooth
    normal /= np.hypot(*normal)
    # the tooth lies inside its tip circle (FS) or outside it (CS): the centre rho off that circle
    outward = 1.0 if along_flank @ C > 0.0 else -1.0
    r_centre = R + outward * rho
    # centre = C + rho normal + s along_flank with |centre| = r_centre: the root with s near t
    P = C + rho * normal
    b, c = along_flank @ P, P @ P - r_centre * r_centre
    s = c / (-b - math.copysign(math.sqrt(b * b - c), b))     # the small root, without cancellation
    centre = P + s * along_flank
    return C + s * along_flank, centre * (R / r_centre), centre, s


def _round_corner(pts, rho: float, land_sign: float):
    """Round the corner at ``pts[0]``: the flank points with ``pts[0]`` replaced by the round's
    tangent point and the points it covers dropped, and (land tangent point, centre)."""
    C = pts[0]
    for k in range(1, len(pts)):
        on_flank, on_land, centre, t = round_corner_geometry(C, pts[k], land_sign, rho)
        if np.hypot(pts[k][0] - C[0], pts[k][1] - C[1]) > 1.5 * t:
            break
    else:
        raise ValueError(f"tip round of radius {rho} mm does not fit on the flank")
    return [tuple(on_flank)] + [tuple(q) for q in pts[k:]], (tuple(on_land), tuple(centre))


def _rim_size_field(prof: RingProfile, sizes: RingSizes, rounds: list[int]) -> None:
    """The element size: the teeth's up to the root circle, then growing linearly in radius to
    the closing circle's (a period is too narrow for sizes extended from its boundary to grade
    like a whole ring's)."""
    rc = float(prof.rr[-1])
    r_start = min((float(prof.rr[0]), rc), key=lambda r: abs(r - prof.r_plain))   # the root circle
    depth = prof.r_plain - r_start            # signed: toward the closing circle
    field = gmsh.model.mesh.field.add("MathEval")
    gmsh.model.mesh.field.setString(field, "F", (
        f"({sizes.tooth!r}) + ({sizes.plain - sizes.tooth!r}) * Max(0, (Sqrt(x*x + y*y) - ({r_start!r})) / ({depth!r}))"))
    if rounds:
        # graded down to the round's segments within 1.5 tooth elements of it (a fan of
        # slivers otherwise), nothing changed beyond
        fine = _curve_length(rounds[0]) / sizes.round_segments
        dist = gmsh.model.mesh.field.add("Distance")
        gmsh.model.mesh.field.setNumbers(dist, "CurvesList", rounds)
        gmsh.model.mesh.field.setNumber(dist, "Sampling", 20)
        thr = gmsh.model.mesh.field.add("Threshold")
        gmsh.model.mesh.field.setNumber(thr, "InField", dist)
        gmsh.model.mesh.field.setNumber(thr, "SizeMin", fine)
        gmsh.model.mesh.field.setNumber(thr, "SizeMax", sizes.tooth)
        gmsh.model.mesh.field.setNumber(thr, "DistMin", 0.0)
        gmsh.model.mesh.field.setNumber(thr, "DistMax", 1.5 * sizes.tooth)
        gmsh.model.mesh.field.setNumber(thr, "StopAtDistMax", 1)
        mn = gmsh.model.mesh.field.add("Min")
        gmsh.model.mesh.field.setNumbers(mn, "FieldsList", [field, thr])
        field = mn
    gmsh.model.mesh.field.setAsBackgroundMesh(field)


def _curve_length(curve: int) -> float:
    """Length (mm) of a gmsh curve, from 21 points along its parametrisation."""
    lo, hi = gmsh.model.getParametrizationBounds(1, curve)
    ts = np.linspace(lo[0], hi[0], 21)
    xyz = np.array(gmsh.model.getValue(1, curve, ts)).reshape(-1, 3)
    return float(np.sum(np.hypot(*np.diff(xyz[:, :2], axis=0).T)))


def _cut_nodes(p: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """A cut's nodes ordered by radius."""
    nodes = np.unique(edges)
    return nodes[np.argsort(np.hypot(*p[:, nodes]))]


def copy_round(sector: SectorMesh, z: int, half: bool) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """The ring of ``z / 2`` (half) or ``z`` copies of ``sector``: nodes (2, N), triangles
    (3, K) and the named edges, each copy's first cut merged with the previous copy's second."""
    alpha = 2.0 * math.pi / z
    n = sector.p.shape[1]
    c0, c1 = sector.cut0, sector.cut1
    r0, r1 = np.hypot(*sector.p[:, c0]), np.hypot(*sector.p[:, c1])
    if c0.size != c1.size or np.abs(r0 - r1).max() > 1e-9 * r0.max():
        raise ValueError("sector mesh: the cuts at 0 and 2 pi / z do not pair up")
    copies = z // 2 if half else z
    fresh = np.setdiff1d(np.arange(n), c0)
    gid = np.empty((copies, n), dtype=np.int64)
    gid[0] = np.arange(n)
    for k in range(1, copies):
        gid[k, fresh] = n + (k - 1) * fresh.size + np.arange(fresh.size)
        gid[k, c0] = gid[k - 1, c1]
    if not half:                       # close the ring: the last copy's second cut is the first cut
        gid[-1, c1] = gid[0, c0]
    used, gid = np.unique(gid, return_inverse=True)
    gid = gid.reshape(copies, n)
    p = np.empty((2, used.size))
    base = sector.p.copy()
    base[1, c0] = 0.0                  # the cut at angle 0 lies on the x axis
    # and the second cut is its exact image (gmsh's periodic copy is off by ~1e-12 mm), so the
    # ring is periodic to round-off: its stiffness then commutes with the turn by a period
    # closely enough for the FS's columns to be turned (``hdwf.fe.ring_columns``)
    base[:, c1] = np.array([[math.cos(alpha), -math.sin(alpha)],
                            [math.sin(alpha), math.cos(alpha)]]) @ base[:, c0]
    for k in range(copies - 1, -1, -1):    # copy 0 last: the merged nodes keep exact positions
        a = k * alpha
        rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        p[:, gid[k]] = rot @ base
    if half:                           # the cut at pi is the image of the cut at 0
        p[:, gid[-1, c1]] = -base[:, c0]
    t = np.hstack([gid[k][sector.t] for k in range(copies)])
    edges = {name: np.vstack([gid[k][e] for k in range(copies)]) for name, e in sector.edges.items()}
    return p, t, edges
