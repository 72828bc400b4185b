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
Hand-written parts: only the tooth outlines (involute points from ``hdwf.drive.geometry``) and
the conversion of gmsh's arrays into per-body scikit-fem meshes.

Half model (``symmetry="half"``): the drive is point-symmetric under a rotation by pi
(even tooth counts, two-lobe cam, even ball count), so only the upper half (angles 0..pi)
of every body is meshed.  Each body is cut along the x axis; the cut line at angle pi is
made gmsh-periodic to the one at angle 0 under the rotation by pi, so every node at
(-x, 0) has a partner at (x, 0) (``hdwf.fe`` ties them, u_partner = -u).  The half
outlines use the same points, flank and arc node counts as the full ones, so the density
rule is unchanged.  ``DriveMesh.symmetry`` says which model it is; the flag is also
recorded as ``sizes["symmetry_half"] = 1.0`` so that it survives storage of ``sizes``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import gmsh
import numpy as np
from skfem import MeshTri

from hdwf.drive.geometry import DriveGeometry, cs_half_space_angle, fs_half_angle
from hdwf.drive.relief import relief_start_depth

MESH_ALGORITHM = 6   # gmsh 2D: 6 = Frontal-Delaunay (quality); 5 = Delaunay
LC_INTEGRATION_PRECISION = 1e-6   # relative precision of the size integral along a curve


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


def _sizes(g: DriveGeometry, n_h: int, n_t: int, refinement: float) -> dict[str, float]:
    h_tooth = g.r_fs_tip - g.r_fs_root
    s_pitch = math.pi * g.module / 2
    nh = max(2, int(round(n_h * refinement)))
    nt = max(2, int(round(n_t * refinement)))
    s = min(h_tooth / nh, s_pitch / nt)
    return dict(
        n_flank=nh,
        tooth=s,
        fs_bore=2.0 * s,
        cs_outer=max(4.0 * s, (g.r_cs_outer - g.r_cs_root) / max(3.0, 4 * refinement)),
        ring=min((g.d1 - g.d) / 2, (g.D - g.D1) / 2) / max(3.0, 6.0 * refinement),
    )


def _circle(geo, r: float, size: float, c: int, nseg: int | None = None) -> list[int]:
    """Full circle as 4 arcs (geo arcs must span < pi), optional transfinite count."""
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


def _toothed_outline(geo, z: int, rr: np.ndarray, half_angle: np.ndarray, c: int,
                     size: float) -> tuple[list[int], list[int]]:
    """Closed toothed outline (counter-clockwise) of z teeth or spaces centred on 2 pi i / z.

    Each period: the clockwise flank at angles -half_angle(r) over the radii ``rr``, an arc
    across (FS tooth tip or CS space root), the other flank back, then the land to the next
    period. Returns (curves, flanks).
    """
    curves, flanks = [], []
    first_pt = prev_pt = None
    for i in range(z):
        th = 2 * math.pi * i / z
        pa = [geo.addPoint(r * math.cos(t), r * math.sin(t), 0.0, size) for r, t in zip(rr, th - half_angle)]
        if prev_pt is not None:     # land from the previous period
            curves.append(geo.addCircleArc(prev_pt, c, pa[0]))
        else:
            first_pt = pa[0]
        fa = geo.addSpline(pa)
        pb = [geo.addPoint(r * math.cos(t), r * math.sin(t), 0.0, size)
              for r, t in zip(rr[::-1], (th + half_angle)[::-1])]
        across = geo.addCircleArc(pa[-1], c, pb[0])
        fb = geo.addSpline(pb)
        curves += [fa, across, fb]
        flanks += [fa, fb]
        prev_pt = pb[-1]
    curves.append(geo.addCircleArc(prev_pt, c, first_pt))
    return curves, flanks


def _toothed_half_outline(geo, z: int, rr: np.ndarray, half_angle: np.ndarray, c: int,
                          size: float):
    """Upper half (angles 0..pi) of ``_toothed_outline``: the same points, starting at the
    middle of period 0 (angle 0, radius rr[-1]) and ending at the middle of period z/2
    (angle pi).  Returns (curves, flanks, first point, last point)."""
    zh = z // 2
    curves, flanks = [], []
    rc = float(rr[-1])
    p0 = geo.addPoint(rc, 0.0, 0.0, size)
    pe = None
    prev = None
    for i in range(zh + 1):
        th = 2 * math.pi * i / z
        if i > 0:
            pa = [geo.addPoint(r * math.cos(t), r * math.sin(t), 0.0, size)
                  for r, t in zip(rr, th - half_angle)]
            curves.append(geo.addCircleArc(prev, c, pa[0]))
            fa = geo.addSpline(pa)
            curves.append(fa)
            flanks.append(fa)
            if i == zh:
                pe = geo.addPoint(-rc, 0.0, 0.0, size)
                curves.append(geo.addCircleArc(pa[-1], c, pe))
                break
        pb = [geo.addPoint(r * math.cos(t), r * math.sin(t), 0.0, size)
              for r, t in zip(rr[::-1], (th + half_angle)[::-1])]
        curves.append(geo.addCircleArc(p0 if i == 0 else pa[-1], c, pb[0]))
        fb = geo.addSpline(pb)
        curves.append(fb)
        flanks.append(fb)
        prev = pb[-1]
    return curves, flanks, p0, pe


def _half_circle(geo, r: float, size: float, c: int):
    """Upper half circle as 2 arcs 0 -> pi/2 -> pi (the full circle's first two arcs)."""
    pts = [geo.addPoint(r * math.cos(a), r * math.sin(a), 0.0, size)
           for a in np.arange(3) * math.pi / 2]
    return [geo.addCircleArc(pts[0], c, pts[1]), geo.addCircleArc(pts[1], c, pts[2])], pts


def _fs_outline(geo, g: DriveGeometry, c: int, s: dict) -> tuple[list[int], list[int]]:
    """Outer outline of the FS: teeth centred on 2 pi i / z_FS, flanks root -> tip."""
    rr = _relieved_radii(g, g.r_fs_root, g.r_fs_tip, g.r_fs_tip)
    return _toothed_outline(geo, g.z_fs, rr, fs_half_angle(g, rr), c, s["tooth"])


def _cs_outline(geo, g: DriveGeometry, c: int, s: dict) -> tuple[list[int], list[int]]:
    """Inner outline of the CS: spaces centred on 2 pi j / z_CS so that FS tooth 0 (angle 0)
    enters CS space 0 at the major axis; flanks tip -> root."""
    rr = _relieved_radii(g, g.r_cs_tip, g.r_cs_root, g.r_cs_tip)
    return _toothed_outline(geo, g.z_cs, rr, cs_half_space_angle(g, rr), c, s["tooth"])


BODY_NAMES = ("fs", "cs", "ir", "or")


def build_mesh(geom: DriveGeometry, elements_over_height: int = 10,
               elements_over_thickness: int = 6, refinement: float = 1.0,
               path: str | None = None, symmetry: str = "full",
               bodies: tuple[str, ...] = BODY_NAMES) -> DriveMesh:
    """Mesh the four bodies (or some); write ``path`` (.msh) if given; return per-body meshes.

    Parameters
    ----------
    geom : the drive's geometry.
    elements_over_height, elements_over_thickness : elements over a tooth (paper: 10 and 6).
    refinement : multiplies both counts.
    path : where gmsh writes its binary ``.msh`` (for review), or None.
    symmetry : ``"half"`` meshes only the upper half of every body (see the module
        docstring); ``"full"`` (default) the whole drive.
    bodies : the bodies to mesh.  Each body has its own curves and surface, so a body meshed
        alone gets the same nodes and triangles as in the whole drive (``share_bodies``).

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
    s = _sizes(g, elements_over_height, elements_over_thickness, refinement)
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("hd")
        geo = gmsh.model.geo
        c = geo.addPoint(0, 0, 0, 1.0)
        groups: dict[str, tuple[int, list[int]]] = {}
        cuts: list[tuple[int, int]] = []     # (line at angle pi, line at angle 0)
        build = _half_geometry if half else _full_geometry
        curves = build(geo, g, c, s, groups, cuts, set(bodies))
        geo.synchronize()
        _mesh_controls(g, s, curves, cuts)
        for name, (dim, tags) in groups.items():
            gmsh.model.addPhysicalGroup(dim, tags, name=name)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 1)
        gmsh.option.setNumber("Mesh.Algorithm", MESH_ALGORITHM)
        # gmsh integrates the size along every curve to 1e-9 by default, a third of the meshing
        # time on ~1000 tooth curves; 1e-6 of a segment changes no size that matters
        gmsh.option.setNumber("Mesh.LcIntegrationPrecision", LC_INTEGRATION_PRECISION)
        gmsh.model.mesh.generate(2)
        if path is not None:
            gmsh.option.setNumber("Mesh.Binary", 1)  # 4x smaller and faster to write; gmsh reads it back
            gmsh.write(str(path))
        ntags, coords, _ = gmsh.model.mesh.getNodes()
        xy = np.zeros((int(ntags.max()) + 1, 2))
        xy[ntags.astype(np.int64)] = coords.reshape(-1, 3)[:, :2]
        meshes = {name: _extract_body(name, groups, xy, thick, bnames) for name, thick, bnames in (
            ("fs", g.face_fs, ["fs_teeth", "fs_bore"]), ("cs", g.face_cs, ["cs_teeth", "cs_outer"]),
            ("ir", g.B, ["ir_bore", "ir_race"]), ("or", g.B, ["or_race", "or_outer"])) if name in bodies}
    finally:
        gmsh.finalize()
    if half:
        s["symmetry_half"] = 1.0
    return DriveMesh(meshes, s, symmetry)


def share_bodies(fs_mesh: DriveMesh, others: DriveMesh) -> DriveMesh:
    """The drive of ``fs_mesh``'s FS with the CS and bearing rings of ``others`` (the same
    objects): for outlines that differ in the FS teeth only (a preload's allowance), whose
    other bodies are then meshed, assembled and factorised once."""
    if fs_mesh.symmetry != others.symmetry or fs_mesh.sizes != others.sizes:
        raise ValueError("share_bodies: the meshes differ in symmetry or density")
    return DriveMesh({"fs": fs_mesh.bodies["fs"], **{n: others.bodies[n] for n in BODY_NAMES[1:]}},
                     dict(others.sizes), others.symmetry)


def _mesh_controls(g: DriveGeometry, s: dict, curves: tuple, cuts: list) -> None:
    """Periodic cuts (half model), transfinite flanks and uniform spacing on circular contacts."""
    fs_fl, cs_fl, fs_bore, ir_bore, ir_race, or_race, or_outer, cs_outer = curves
    # half model: the cut at angle pi is the image of the cut at angle 0 under the
    # rotation by pi, so their nodes pair up exactly (u_pi = -u_0 in hdwf.fe)
    rot_pi = [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    for slave, master in cuts:
        gmsh.model.mesh.setPeriodic(1, [slave], [master], rot_pi)
    # transfinite flanks: exactly n_flank segments over the tooth height
    for cv in fs_fl + cs_fl:
        gmsh.model.mesh.setTransfiniteCurve(cv, s["n_flank"] + 1)

    # uniform node spacing on the circular contact surfaces (mortar bins need no
    # matching, but uniform spacing keeps the bin weights even)
    def uniform(arcs, r, h):
        n = max(2, int(math.ceil(0.5 * math.pi * r / h)))
        for a in arcs:
            gmsh.model.mesh.setTransfiniteCurve(a, n + 1)
    uniform(fs_bore, g.r_fs_bore, s["fs_bore"])
    for arcs, r in ((ir_bore, g.ir_bore), (ir_race, g.ir_race), (or_race, g.or_race), (or_outer, g.or_outer)):
        uniform(arcs, r, s["ring"])
    uniform(cs_outer, g.r_cs_outer, s["cs_outer"])


def _extract_body(name: str, groups: dict, xy: np.ndarray, thickness: float, boundary_names: list[str]) -> BodyMesh:
    """One body's triangles (counter-clockwise, local numbering) and its named boundaries."""
    surf = groups[name][1][0]
    et, _, enodes = gmsh.model.mesh.getElements(2, surf)
    tri = np.asarray(enodes[list(et).index(2)], dtype=np.int64).reshape(-1, 3)
    used = np.unique(tri)
    loc = -np.ones(xy.shape[0], dtype=np.int64)
    loc[used] = np.arange(used.size)
    p = xy[used].T.copy()
    t = loc[tri].T.copy()
    a = ((p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
         - (p[0, t[2]] - p[0, t[0]]) * (p[1, t[1]] - p[1, t[0]]))
    sw = a < 0
    t[1, sw], t[2, sw] = t[2, sw].copy(), t[1, sw].copy()
    bm = BodyMesh(name, MeshTri(p, t), thickness)
    for bn in boundary_names:
        edges = []
        for cv in groups[bn][1]:
            et1, _, en1 = gmsh.model.mesh.getElements(1, cv)
            edges.append(np.asarray(en1[list(et1).index(1)], dtype=np.int64).reshape(-1, 2))
        e = loc[np.vstack(edges)]
        bm.edge_sets[bn] = e
        bm.node_sets[bn] = np.unique(e)
    return bm


def _full_geometry(geo, g: DriveGeometry, c: int, s: dict, groups: dict, cuts: list, bodies: set):
    """The whole bodies named in ``bodies`` (FS, CS, bearing inner and outer ring); fills ``groups``.

    ``cuts`` stays empty (no symmetry cut); same signature and return as ``_half_geometry``
    (the curves of a body not built are empty)."""
    fs_fl = cs_fl = fs_bore = cs_outer = ir_bore = ir_race = or_race = or_outer = []
    if "fs" in bodies:
        fs_out, fs_fl = _fs_outline(geo, g, c, s)
        fs_bore = _circle(geo, g.r_fs_bore, s["fs_bore"], c)
        fs_surf = geo.addPlaneSurface([geo.addCurveLoop(fs_out), geo.addCurveLoop(fs_bore)])
        groups.update({"fs": (2, [fs_surf]), "fs_teeth": (1, fs_out), "fs_bore": (1, fs_bore)})
    if "cs" in bodies:
        cs_in, cs_fl = _cs_outline(geo, g, c, s)
        cs_outer = _circle(geo, g.r_cs_outer, s["cs_outer"], c)
        cs_surf = geo.addPlaneSurface([geo.addCurveLoop(cs_outer), geo.addCurveLoop(cs_in)])
        groups.update({"cs": (2, [cs_surf]), "cs_teeth": (1, cs_in), "cs_outer": (1, cs_outer)})
    if "ir" in bodies:
        ir_bore = _circle(geo, g.ir_bore, s["ring"], c)
        ir_race = _circle(geo, g.ir_race, s["ring"], c)
        ir_surf = geo.addPlaneSurface([geo.addCurveLoop(ir_race), geo.addCurveLoop(ir_bore)])
        groups.update({"ir": (2, [ir_surf]), "ir_bore": (1, ir_bore), "ir_race": (1, ir_race)})
    if "or" in bodies:
        or_race = _circle(geo, g.or_race, s["ring"], c)
        or_outer = _circle(geo, g.or_outer, s["ring"], c)
        or_surf = geo.addPlaneSurface([geo.addCurveLoop(or_outer), geo.addCurveLoop(or_race)])
        groups.update({"or": (2, [or_surf]), "or_race": (1, or_race), "or_outer": (1, or_outer)})
    return fs_fl, cs_fl, fs_bore, ir_bore, ir_race, or_race, or_outer, cs_outer


def _half_geometry(geo, g: DriveGeometry, c: int, s: dict, groups: dict, cuts: list, bodies: set):
    """Upper halves of the bodies named in ``bodies``, each closed by two radial cut lines on
    the x axis (inner -> outer radius at angle 0 and at angle pi); fills ``groups`` and ``cuts``."""
    def cut_pair(p_in0, p_out0, p_in1, p_out1):
        l0 = geo.addLine(p_in0, p_out0)
        l1 = geo.addLine(p_in1, p_out1)
        cuts.append((l1, l0))
        return l0, l1

    fs_fl = cs_fl = fs_bore = cs_outer = ir_bore = ir_race = or_race = or_outer = []
    if "fs" in bodies:    # toothed outline 0 -> pi, bore pi -> 0
        rr = _relieved_radii(g, g.r_fs_root, g.r_fs_tip, g.r_fs_tip)
        fs_out, fs_fl, o0, o1 = _toothed_half_outline(geo, g.z_fs, rr, fs_half_angle(g, rr), c,
                                                      s["tooth"])
        fs_bore, bp = _half_circle(geo, g.r_fs_bore, s["fs_bore"], c)
        l0, l1 = cut_pair(bp[0], o0, bp[2], o1)
        loop = fs_out + [-l1] + [-a for a in fs_bore[::-1]] + [l0]
        fs_surf = geo.addPlaneSurface([geo.addCurveLoop(loop)])
        groups.update({"fs": (2, [fs_surf]), "fs_teeth": (1, fs_out), "fs_bore": (1, fs_bore)})
    if "cs" in bodies:    # outer rim 0 -> pi, toothed inner outline pi -> 0
        rr = _relieved_radii(g, g.r_cs_tip, g.r_cs_root, g.r_cs_tip)
        cs_in, cs_fl, i0, i1 = _toothed_half_outline(geo, g.z_cs, rr, cs_half_space_angle(g, rr),
                                                     c, s["tooth"])
        cs_outer, op = _half_circle(geo, g.r_cs_outer, s["cs_outer"], c)
        l0, l1 = cut_pair(i0, op[0], i1, op[2])
        loop = [l0] + cs_outer + [-l1] + [-a for a in cs_in[::-1]]
        cs_surf = geo.addPlaneSurface([geo.addCurveLoop(loop)])
        groups.update({"cs": (2, [cs_surf]), "cs_teeth": (1, cs_in), "cs_outer": (1, cs_outer)})

    def ring(r_in, r_out):
        inner, ip = _half_circle(geo, r_in, s["ring"], c)
        outer, op = _half_circle(geo, r_out, s["ring"], c)
        l0, l1 = cut_pair(ip[0], op[0], ip[2], op[2])
        loop = [l0] + outer + [-l1] + [-a for a in inner[::-1]]
        return geo.addPlaneSurface([geo.addCurveLoop(loop)]), inner, outer
    if "ir" in bodies:
        ir_surf, ir_bore, ir_race = ring(g.ir_bore, g.ir_race)
        groups.update({"ir": (2, [ir_surf]), "ir_bore": (1, ir_bore), "ir_race": (1, ir_race)})
    if "or" in bodies:
        or_surf, or_race, or_outer = ring(g.or_race, g.or_outer)
        groups.update({"or": (2, [or_surf]), "or_race": (1, or_race), "or_outer": (1, or_outer)})
    return fs_fl, cs_fl, fs_bore, ir_bore, ir_race, or_race, or_outer, cs_outer


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
        ntags, coords, _ = gmsh.model.mesh.getNodes()
        xy = np.zeros((int(ntags.max()) + 1, 2))
        xy[ntags.astype(np.int64)] = coords.reshape(-1, 3)[:, :2]
        et, _, en = gmsh.model.mesh.getElements(2, surf)
        tri = np.asarray(en[list(et).index(2)], dtype=np.int64).reshape(-1, 3)
        used = np.unique(tri)
        loc = -np.ones(xy.shape[0], dtype=np.int64)
        loc[used] = np.arange(used.size)
        p, t = xy[used].T.copy(), loc[tri].T.copy()
        a = ((p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
             - (p[0, t[2]] - p[0, t[0]]) * (p[1, t[1]] - p[1, t[0]]))
        sw = a < 0
        t[1, sw], t[2, sw] = t[2, sw].copy(), t[1, sw].copy()
        bm = BodyMesh("ring", MeshTri(p, t), 1.0)
        for name, arcs in (("inner", inner), ("outer", outer)):
            edges = []
            for cv in arcs:
                et1, _, en1 = gmsh.model.mesh.getElements(1, cv)
                edges.append(np.asarray(en1[list(et1).index(1)], dtype=np.int64).reshape(-1, 2))
            e = loc[np.vstack(edges)]
            bm.edge_sets[name], bm.node_sets[name] = e, np.unique(e)
    finally:
        gmsh.finalize()
    return bm
