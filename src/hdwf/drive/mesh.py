"""Plane (2D section) meshes of one harmonic-drive design, built with the gmsh Python API.

Four separate bodies, meshed with linear triangles and returned as scikit-fem ``MeshTri``:

* ``fs``  flexspline ring: bore (made to the nominal bearing OD) + all 240 external teeth;
* ``cs``  circular-spline ring: all 242 internal teeth + outer rim (the support);
* ``ir``  bearing inner ring: bore d (sits on the cam) to raceway d1;
* ``or``  bearing outer ring: raceway D1 to outer diameter D (sits in the FS bore).

The balls are NOT meshed: each is a discrete unilateral Hertz element between the two
raceways (see ``hdwf.fe``); the cam is a rigid analytic curve (``hdwf.drive.geometry``), not
meshed either.  Only the contact surfaces need to be named; physical groups:
``fs_bore``, ``fs_teeth`` (flanks, tips and roots), ``cs_teeth``, ``cs_outer`` (support),
``ir_bore``, ``ir_race``, ``or_race``, ``or_outer`` and one surface group per body.

Density follows the paper (Sec. 4): each tooth flank is split into ``elements_over_height``
segments and the tooth thickness at the pitch circle into ``elements_over_thickness``;
the rim grades to about twice that size at the FS bore and to a coarse size at the CS
outer rim.  ``refinement`` multiplies every element count (divides every size).
The FS and CS are meshed as one tooth period and copied round (``hdwf.drive.sector_mesh``:
every tooth gets the same nodes); the bearing rings are meshed whole by gmsh.
Hand-written parts: only the tooth outlines (involute points from ``hdwf.drive.geometry``),
the copying and the conversion of gmsh's arrays into per-body scikit-fem meshes.

Half model (``symmetry="half"``): the drive is point-symmetric under a rotation by pi
(even tooth counts, two-lobe cam, even ball count), so only the upper half (angles 0..pi)
of every body is meshed.  Each body is cut along the x axis; the cut at angle pi is the
image of the one at angle 0 under the rotation by pi (gmsh-periodic on the bearing rings, by
construction on the toothed rings, whose cuts run through the middle of a FS tooth or CS
space), so every node at (-x, 0) has a partner at (x, 0) (``hdwf.fe`` ties them,
u_partner = -u).  The half model uses the same period and ring node counts as the full one,
so the density rule is unchanged.  ``DriveMesh.symmetry`` says which model it is; the flag is also
recorded as ``sizes["symmetry_half"] = 1.0`` so that it survives storage of ``sizes``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import gmsh
import numpy as np
from skfem import MeshTri

from hdwf.drive.geometry import DriveGeometry, cs_half_space_angle, fs_half_angle
from hdwf.drive.gmsh_read import read_surface
from hdwf.drive.relief import relief_start_depth
from hdwf.drive.sector_mesh import RingProfile, RingSizes, copy_round, mesh_period

MESH_ALGORITHM = 6   # gmsh 2D: 6 = Frontal-Delaunay (quality); 5 = Delaunay
LC_INTEGRATION_PRECISION = 1e-6   # relative precision of the size integral along a curve
# narrower teeth or spaces (units of the module) are refused: gmsh never returns on a tooth
# period whose neighbouring FS teeth meet at the root (HD 42 Table 4 set 27 at an allowance of
# 0.4 m) or whose CS tips are relieved away (hd120-lhs-11 at 3 times the derived relief)
MIN_FEATURE_M = 0.1


@dataclass
class BodyMesh:
    name: str
    mesh: MeshTri
    thickness: float                       # plane-stress thickness (face width), mm
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)   # group -> node ids
    edge_sets: dict[str, np.ndarray] = field(default_factory=dict)   # group -> (k, 2) ids


@dataclass
class DriveMesh:
    bodies: dict[str, BodyMesh]
    sizes: dict[str, float]
    symmetry: str = "full"                 # "full" or "half" (upper half, angles 0..pi)

    def __post_init__(self):
        # a mesh read back from storage carries only ``sizes``: the flag lives there too
        if float(self.sizes.get("symmetry_half", 0.0)) == 1.0:
            self.symmetry = "half"

    @property
    def n_nodes(self) -> int:
        return sum(b.mesh.p.shape[1] for b in self.bodies.values())


def _count(n: float) -> int:
    return max(2, int(round(n)))


def flank_segments(n_h: int, refinement: float = 1.0, flank_refinement: float = 1.0) -> int:
    """The segments along every flank of a mesh of these settings (``build_mesh``)."""
    return _count(_count(n_h * refinement) * flank_refinement)


def _sizes(g: DriveGeometry, n_h: int, n_t: int, refinement: float,
           flank_refinement: float = 1.0) -> dict[str, float]:
    h_tooth = g.r_fs_tip - g.r_fs_root
    s_pitch = math.pi * g.module / 2
    nh, nt = _count(n_h * refinement), _count(n_t * refinement)
    s = min(h_tooth / nh, s_pitch / nt)
    return dict(
        n_flank=flank_segments(n_h, refinement, flank_refinement),
        tooth=s,
        fs_bore=2.0 * s,
        cs_outer=max(4.0 * s, (g.r_cs_outer - g.r_cs_root) / max(3.0, 4 * refinement)),
        ring=min((g.d1 - g.d) / 2, (g.D - g.D1) / 2) / max(3.0, 6.0 * refinement),
    )


def _circle(geo, r: float, size: float, c: int) -> list[int]:
    """Full circle as 4 arcs (geo arcs must span < pi)."""
    pts = [geo.addPoint(r * math.cos(a), r * math.sin(a), 0.0, size)
           for a in np.arange(4) * math.pi / 2]
    arcs = [geo.addCircleArc(pts[i], c, pts[(i + 1) % 4]) for i in range(4)]
    return arcs


def _flank_radii(r0: float, r1: float, n: int) -> np.ndarray:
    return np.linspace(r0, r1, n)


def _relieved_radii(g: DriveGeometry, r0: float, r1: float, r_tip: float) -> np.ndarray:
    """The flank's spline radii r0 -> r1 (12, as without relief); with tip relief also 8
    over the relieved depth below ``r_tip``, so the spline follows the relief curve
    (``hdwf.drive.relief``)."""
    rr = _flank_radii(r0, r1, 12)
    if not g.tip_relief:
        return rr
    d0 = min(relief_start_depth(g.module, g.addendum, g.alpha, g.tilt_factor), abs(r1 - r0))
    toward_root = 1.0 if r_tip > min(r0, r1) else -1.0      # FS tip outside, CS tip inside
    extra = r_tip - toward_root * np.linspace(0.0, d0, 9)
    rr = np.unique(np.concatenate([rr, extra]))
    return rr if r1 > r0 else rr[::-1]


BODY_NAMES = ("fs", "cs", "ir", "or")


def _round_segments(s: dict) -> int:
    """Segments on a tip round: a fifth of a flank's, at least 2 (2 on the default mesh)."""
    return max(2, int(round(s["n_flank"] / 5)))


def build_mesh(geom: DriveGeometry, elements_over_height: int = 10,
               elements_over_thickness: int = 6, refinement: float = 1.0,
               path: str | None = None, symmetry: str = "full",
               bodies: tuple[str, ...] = BODY_NAMES, flank_refinement: float = 1.0) -> DriveMesh:
    """Mesh the four bodies (or some); write ``path`` (.msh) if given; return per-body meshes.

    Parameters
    ----------
    geom : the drive's geometry.
    elements_over_height, elements_over_thickness : elements over a tooth (paper: 10 and 6).
    refinement : multiplies both counts.
    path : where gmsh writes its binary ``.msh`` (for review), or None.
    symmetry : ``"half"`` meshes only the upper half of every body (see the module
        docstring); ``"full"`` (default) the whole drive.
    bodies : the bodies to mesh.  Each body is meshed on its own, so a body meshed alone is
        the same as in the whole drive (``share_bodies``).
    flank_refinement : multiplies the segments along every flank only (on top of
        ``refinement``; the element size inside the teeth stays): the flank contact needs a
        finer division than the teeth's elasticity (``docs/fe-model.md``, Mesh convergence).

    Returns
    -------
    DriveMesh : the FS, CS and bearing rings (those asked for) with their named node and edge sets.
    """
    g = geom
    if symmetry not in ("full", "half"):
        raise ValueError(f"symmetry must be 'full' or 'half', not {symmetry!r}")
    half = symmetry == "half"
    unknown = set(bodies) - set(BODY_NAMES)
    if unknown or not bodies:
        raise ValueError(f"bodies must be some of {BODY_NAMES}, not {bodies!r}")
    if half and (g.z_fs % 2 or g.z_cs % 2 or g.n_balls % 2):
        raise ValueError("half model needs even tooth and ball counts (180 deg symmetry)")
    if flank_refinement <= 0:
        raise ValueError(f"flank_refinement must be positive, not {flank_refinement!r}")
    s = _sizes(g, elements_over_height, elements_over_thickness, refinement, flank_refinement)
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        meshes = {name: _toothed_body(name, g, s, half) for name in ("fs", "cs") if name in bodies}
        rings = tuple(name for name in ("ir", "or") if name in bodies)
        if rings:
            meshes.update(_bearing_rings(g, s, half, rings))
        if path is not None:
            _write_review(str(path), meshes)
    finally:
        gmsh.finalize()
    if half:
        s["symmetry_half"] = 1.0
    return DriveMesh({name: meshes[name] for name in BODY_NAMES if name in meshes}, s, symmetry)


def share_bodies(fs_mesh: DriveMesh, others: DriveMesh) -> DriveMesh:
    """The drive of ``fs_mesh``'s FS with the CS and bearing rings of ``others`` (the same
    objects): for outlines that differ in the FS teeth only (a preload's allowance), whose
    other bodies are then meshed, assembled and factorised once."""
    if fs_mesh.symmetry != others.symmetry or fs_mesh.sizes != others.sizes:
        raise ValueError("share_bodies: the meshes differ in symmetry or density")
    return DriveMesh({"fs": fs_mesh.bodies["fs"], **{n: others.bodies[n] for n in BODY_NAMES[1:]}},
                     dict(others.sizes), others.symmetry)


def _toothed_body(name: str, g: DriveGeometry, s: dict, half: bool) -> BodyMesh:
    """The FS (teeth centred on 2 pi i / z_FS, flanks root -> tip) or the CS (spaces centred on
    2 pi j / z_CS, so that FS tooth 0 enters CS space 0 at the major axis), one period meshed
    and copied round (``hdwf.drive.sector_mesh``)."""
    if name == "fs":
        rr = _relieved_radii(g, g.r_fs_root, g.r_fs_tip, g.r_fs_tip)
        prof = RingProfile(g.z_fs, rr, fs_half_angle(g, rr), g.r_fs_bore, "fs_teeth", "fs_bore",
                           g.tip_round, True)
        sizes, thickness = RingSizes(s["tooth"], s["fs_bore"], int(s["n_flank"]), _round_segments(s)), g.face_fs
    else:
        rr = _relieved_radii(g, g.r_cs_tip, g.r_cs_root, g.r_cs_tip)
        prof = RingProfile(g.z_cs, rr, cs_half_space_angle(g, rr), g.r_cs_outer, "cs_teeth", "cs_outer",
                           g.tip_round, False)
        sizes, thickness = RingSizes(s["tooth"], s["cs_outer"], int(s["n_flank"]), _round_segments(s)), g.face_cs
    _check_widths(name, prof, g)
    sector = mesh_period(prof, sizes, MESH_ALGORITHM, LC_INTEGRATION_PRECISION)
    p, t, edges = copy_round(sector, prof.z, half)
    bm = BodyMesh(name, MeshTri(p, _counter_clockwise(p, t)), thickness)
    for group, e in edges.items():
        bm.edge_sets[group], bm.node_sets[group] = e, np.unique(e)
    return bm


def _check_widths(name: str, prof: RingProfile, g: DriveGeometry) -> None:
    """Refuse an outline whose teeth or spaces are narrower than ``MIN_FEATURE_M`` anywhere along
    the flank (arc widths): not a gear anyone makes, and a shape the mesher never returns on."""
    middle = 2.0 * prof.half_angle * prof.rr               # FS tooth or CS space
    between = (2.0 * math.pi / prof.z - 2.0 * prof.half_angle) * prof.rr
    kinds = ("tooth", "space") if name == "fs" else ("space", "tooth")
    for kind, width in zip(kinds, (middle, between)):
        k = int(np.argmin(width))
        if width[k] < MIN_FEATURE_M * g.module:
            raise ValueError(
                f"{name.upper()} {kind} only {width[k] / g.module:.3f} m wide at r = {prof.rr[k]:.4f} mm "
                f"(at least {MIN_FEATURE_M} m is meshed): interference_m={g.interference_m:g}, "
                f"tip_relief={g.tip_relief:g}, r_FS={g.r_fs:g} mm, r_CS={g.r_cs:g} mm")


def _counter_clockwise(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    t = t.copy()
    a = ((p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
         - (p[0, t[2]] - p[0, t[0]]) * (p[1, t[1]] - p[1, t[0]]))
    sw = a < 0
    t[1, sw], t[2, sw] = t[2, sw].copy(), t[1, sw].copy()
    return t


def _bearing_rings(g: DriveGeometry, s: dict, half: bool, rings: tuple[str, ...]) -> dict[str, BodyMesh]:
    """The bearing's inner and outer ring (those in ``rings``), meshed by gmsh as whole rings or
    upper halves with uniform node spacing on their circles."""
    gmsh.model.add("bearing")
    geo = gmsh.model.geo
    c = geo.addPoint(0, 0, 0, 1.0)
    groups: dict[str, tuple[int, list[int]]] = {}
    cuts: list[tuple[int, int]] = []     # (line at angle pi, line at angle 0)
    spec = {"ir": (g.ir_bore, g.ir_race, "ir_bore", "ir_race"), "or": (g.or_race, g.or_outer, "or_race", "or_outer")}
    circles = []
    for name in rings:
        r_in, r_out, g_in, g_out = spec[name]
        surf, inner, outer = (_half_ring if half else _whole_ring)(geo, c, r_in, r_out, s["ring"], cuts)
        groups.update({name: (2, [surf]), g_in: (1, inner), g_out: (1, outer)})
        circles += [(inner, r_in), (outer, r_out)]
    geo.synchronize()
    # half model: the cut at angle pi is the image of the cut at angle 0 under the rotation by
    # pi, so their nodes pair up exactly (u_pi = -u_0 in hdwf.fe)
    rot_pi = [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    for slave, master in cuts:
        gmsh.model.mesh.setPeriodic(1, [slave], [master], rot_pi)
    # uniform node spacing on the circular contact surfaces (mortar bins need no matching, but
    # uniform spacing keeps the bin weights even)
    for arcs, r in circles:
        n = max(2, int(math.ceil(0.5 * math.pi * r / s["ring"])))
        for a in arcs:
            gmsh.model.mesh.setTransfiniteCurve(a, n + 1)
    for name, (dim, tags) in groups.items():
        gmsh.model.addPhysicalGroup(dim, tags, name=name)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 1)
    gmsh.option.setNumber("Mesh.Algorithm", MESH_ALGORITHM)
    gmsh.option.setNumber("Mesh.LcIntegrationPrecision", LC_INTEGRATION_PRECISION)
    gmsh.model.mesh.generate(2)
    return {name: _body_of_surface(name, groups[name][1][0], g.B,
                                   {bn: groups[bn][1] for bn in spec[name][2:]}) for name in rings}


def _write_review(path: str, meshes: dict[str, BodyMesh]) -> None:
    """Write the bodies into one binary gmsh ``.msh`` (for review), each a discrete surface
    with its named boundaries as physical groups."""
    gmsh.model.add("review")
    offset = 0
    for name, bm in meshes.items():
        p, t = bm.mesh.p, bm.mesh.t
        tags = offset + 1 + np.arange(p.shape[1])
        surf = gmsh.model.addDiscreteEntity(2)
        xyz = np.vstack([p, np.zeros(p.shape[1])]).T.ravel()
        gmsh.model.mesh.addNodes(2, surf, tags, xyz)
        gmsh.model.mesh.addElementsByType(surf, 2, [], tags[t.T].ravel())
        gmsh.model.addPhysicalGroup(2, [surf], name=name)
        for group, e in bm.edge_sets.items():
            line = gmsh.model.addDiscreteEntity(1)
            gmsh.model.mesh.addElementsByType(line, 1, [], tags[e].ravel())
            gmsh.model.addPhysicalGroup(1, [line], name=group)
        offset += p.shape[1]
    gmsh.option.setNumber("Mesh.Binary", 1)  # 4x smaller and faster to write; gmsh reads it back
    gmsh.write(path)


def _body_of_surface(name: str, surface: int, thickness: float, boundaries: dict[str, list[int]]) -> BodyMesh:
    """The body meshed on gmsh surface ``surface`` (triangles counter-clockwise, its own
    numbering) with its named boundaries (name -> gmsh curves)."""
    read = read_surface(surface)
    bm = BodyMesh(name, MeshTri(read.points, _counter_clockwise(read.points, read.triangles)), thickness)
    for bn, curves in boundaries.items():
        e = read.curve_edges(curves)
        bm.edge_sets[bn], bm.node_sets[bn] = e, np.unique(e)
    return bm


def _whole_ring(geo, c: int, r_in: float, r_out: float, size: float, cuts: list):
    """A whole annulus: its surface and its inner and outer arcs (``cuts`` unused)."""
    inner, outer = _circle(geo, r_in, size, c), _circle(geo, r_out, size, c)
    return geo.addPlaneSurface([geo.addCurveLoop(outer), geo.addCurveLoop(inner)]), inner, outer


def _half_circle(geo, r: float, size: float, c: int):
    """Upper half circle as 2 arcs 0 -> pi/2 -> pi (the full circle's first two arcs)."""
    pts = [geo.addPoint(r * math.cos(a), r * math.sin(a), 0.0, size)
           for a in np.arange(3) * math.pi / 2]
    return [geo.addCircleArc(pts[0], c, pts[1]), geo.addCircleArc(pts[1], c, pts[2])], pts


def _half_ring(geo, c: int, r_in: float, r_out: float, size: float, cuts: list):
    """The upper half of an annulus, closed by radial cuts at angle 0 and pi (added to ``cuts``)."""
    inner, ip = _half_circle(geo, r_in, size, c)
    outer, op = _half_circle(geo, r_out, size, c)
    l0, l1 = geo.addLine(ip[0], op[0]), geo.addLine(ip[2], op[2])
    cuts.append((l1, l0))
    loop = [l0] + outer + [-l1] + [-a for a in inner[::-1]]
    return geo.addPlaneSurface([geo.addCurveLoop(loop)]), inner, outer


def annulus_mesh(r_in: float, r_out: float, size: float) -> BodyMesh:
    """Plain ring (for verification tests): groups ``inner`` and ``outer``."""
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("annulus")
        geo = gmsh.model.geo
        c = geo.addPoint(0, 0, 0, size)
        inner = _circle(geo, r_in, size, c)
        outer = _circle(geo, r_out, size, c)
        surf = geo.addPlaneSurface([geo.addCurveLoop(outer), geo.addCurveLoop(inner)])
        geo.synchronize()
        gmsh.model.addPhysicalGroup(2, [surf], name="ring")
        gmsh.model.mesh.generate(2)
        return _body_of_surface("ring", surf, 1.0, {"inner": inner, "outer": outer})
    finally:
        gmsh.finalize()
