"""Contact rows: the linearised gaps g = g0 + G u_watch >= 0 of every contact pair.

Contacts (unilateral; the flanks may carry friction, ``friction``), one block of rows each:

* cam - IR bore: node-to-rigid-curve, gap and normal re-evaluated at the deformed
  configuration and re-linearised until the geometry update is below 1e-6 mm (``cycle``);
* balls: discrete elements between raceway arcs (radial; each row is the exact P1 mean of
  u_r over an arc of +-ball_dia/8, fixed in mm so the patch does not depend on the mesh),
  initial gap G_r / 2, and a Hertz law delta = c P^(2/3) (exact elliptic-contact Hertz, both
  raceways in series, ``hertz``) added as a secant compliance to the diagonal; secant updated
  to convergence (``solver``);
* OR outer - FS bore: mortar-type bins (piecewise-constant pressure over 1 deg arcs;
  exact P1 mean of u_r of each side over the arc), initial gap (D_nom - D)/2 from the fit.
  Both arc rows integrate the field along the boundary edges instead of averaging the
  nodes that fall inside: node-count averages made the WG stiffness, and so Phi of HD 42,
  jump by up to 4 % from one mesh to the next;
* FS - CS flanks: node-to-segment in two passes (FS flank/tip nodes against CS boundary
  segments; CS tip-land and tip-corner nodes against FS boundary segments), a node beyond
  the end of its closest segment measuring its distance to that corner (its offset along
  the segment's normal is the gap to the segment's straight extension: FS flank nodes
  beside a CS tip "touched" the extension of the tip land, a false contact that came and
  went with the node spacing and moved Phi of hd42-lhs-22 by 2.5 % between meshes),
  built at the wave-generator-deflected configuration (gaps evaluated at the deformed FS)
  and linearised about it (small deformation on top of the deflected state).  Every tooth
  pair also has a slip row (tangent to the master segment) for flank friction.  With a
  flank layer every pair has a compliance in series: its node's share of the layer's
  pressure (overlap / c) integrated along the slave outline (``LayerEdges``; the share
  depends on the gaps, so the solver iterates it as it does the balls' Hertz secants).

Half model: contacts cover angles [0, pi) only, each standing for itself and its image:
balls 0 .. n/2-1 (ball 0 on the cut), fit bins over [0, pi), cam rows and tooth slave nodes
on the half; the tied nodes at angle pi are left out of every row (their rows would repeat
their partners'), and a ball patch or fit bin reaching below angle 0 uses the images near
pi (same radial motion).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from hdwf.drive.cam import cam_points
from hdwf.drive.geometry import DriveGeometry
from hdwf.fe.bodies import Body
from hdwf.fe.contact_geometry import closest_on_cam, match_to_outline
from hdwf.fe.flank_layer import LayerEdges, LayerPass, layer_edges
from hdwf.fe.structure import Structure

BALL_PATCH_FRAC = 0.125  # ball load spread over +-ball_dia/8 of raceway arc
CS_TIP_BAND = 0.05       # CS slave nodes of the second contact pass: tip land and corners

PairId = tuple[str, int]   # (kind of rows, row index): one contact pair


@dataclass(frozen=True)
class Rows:
    """A block of contact pairs: sparse rows over the watch vector and gap constants.

    Tooth rows also carry their slip rows (friction), the FS tooth of every pair and the
    slave nodes they were built from (to re-pair the same nodes later).
    """
    kind: str
    G: sp.csr_matrix                          # (n, nwatch); gap g = g0 + G u_watch
    g0: np.ndarray
    slip: sp.csr_matrix | None = None         # (n, nwatch) tangential slip rows
    tooth: np.ndarray | None = None           # FS tooth id of every pair
    slave_nodes: tuple[np.ndarray, np.ndarray] | None = None   # (FS nodes, CS nodes)
    compliance: np.ndarray | None = None      # (n,) mm/N of a layer in series with each pair
    layer: LayerEdges | None = None           # the slave edges the layer's overlap is integrated on


@dataclass(frozen=True)
class StackedRows:
    """All contact rows of a model stacked in the order of their kinds."""
    G: sp.csr_matrix
    g0: np.ndarray
    ids: list[PairId]
    compliance: np.ndarray        # (n,) mm/N in series with each pair (0: none)


def stack_rows(rows: dict[str, Rows]) -> StackedRows:
    """Stack every block of ``rows`` into one gap operator.

    Parameters
    ----------
    rows : dict[str, Rows]
        The blocks by kind; stacked in insertion order.

    Returns
    -------
    StackedRows
        G, g0 and the pair id (kind, row) of every row.
    """
    kinds = list(rows)
    G = sp.vstack([rows[k].G for k in kinds]).tocsr()
    g0 = np.concatenate([rows[k].g0 for k in kinds])
    ids = [(k, i) for k in kinds for i in range(rows[k].G.shape[0])]
    compliance = np.concatenate([rows[k].compliance if rows[k].compliance is not None
                                 else np.zeros(rows[k].G.shape[0]) for k in kinds])
    return StackedRows(G, g0, ids, compliance)


def stack_slip_rows(rows: dict[str, Rows], nwatch: int) -> sp.csr_matrix:
    """Slip rows of every pair in the order of ``stack_rows``.

    Parameters
    ----------
    rows : dict[str, Rows]
        The blocks by kind.
    nwatch : int
        Length of the watch vector.

    Returns
    -------
    scipy.sparse.csr_matrix
        One slip row per pair (zero rows for the blocks without slip rows: all but teeth).
    """
    return sp.vstack([rows[k].slip if rows[k].slip is not None
                      else sp.csr_matrix((rows[k].G.shape[0], nwatch))
                      for k in rows]).tocsr()


def slip_rows_of(rows: dict[str, Rows], ids: list[PairId], nwatch: int) -> sp.csr_matrix:
    """Slip rows (tangent to the master flank) of some pairs.

    Parameters
    ----------
    rows : dict[str, Rows]
        The blocks by kind.
    ids : list of (kind, row)
        The pairs.
    nwatch : int
        Length of the watch vector.

    Returns
    -------
    scipy.sparse.csr_matrix
        One row per pair of ``ids``, zero for pairs that are not tooth pairs.
    """
    out = []
    for k, i in ids:
        gt = rows[k].slip
        out.append(gt[i] if gt is not None else sp.csr_matrix((1, nwatch)))
    return sp.vstack(out).tocsr() if out else sp.csr_matrix((0, nwatch))


# --------------------------------------------------------------------------------------
# Mean radial displacement over arcs (balls and fit)
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Arcs:
    """Arcs [centre - half_width, centre + half_width] of a circle, angles periodic in ``period``."""
    centres: np.ndarray
    half_width: float
    period: float


def _arc_average_rows(body: Body, edges: np.ndarray, arcs: _Arcs, sign: float,
                      nwatch: int) -> sp.csr_matrix:
    """Rows giving sign * the mean radial displacement over the arcs of a circular
    boundary (mortar-type).

    The P1 field is integrated exactly along the boundary edges (in angle), so a row
    does not depend on which nodes happen to fall inside its arc: the mesh only changes
    the quadrature, not the definition.  The period is pi in the half model: an arc
    reaching below 0 uses the edges near pi, whose radial motion is that of their images."""
    p = body.x
    per, half_width = arcs.period, arcs.half_width
    th = np.arctan2(p[1], p[0])
    n1, n2 = edges[:, 0], edges[:, 1]
    dt = np.angle(np.exp(1j * (th[n2] - th[n1])))          # signed edge span
    r, c, v = [], [], []
    for i, cen in enumerate(arcs.centres):
        # edge end angles relative to the centre, wrapped into (-per/2, per/2]
        a1 = (th[n1] - cen + per / 2) % per - per / 2
        a2 = a1 + dt
        lo, hi = np.minimum(a1, a2), np.maximum(a1, a2)
        s_lo, s_hi = np.maximum(lo, -half_width), np.minimum(hi, half_width)
        on = s_hi > s_lo
        if not on.any():
            raise ValueError(f"{body.name}: no boundary edge within the arc at "
                             f"{math.degrees(cen):.2f} deg")
        L = (hi - lo)[on]
        # integral of the hat functions of the edge's two nodes over the overlap
        t_lo, t_hi = s_lo[on], s_hi[on]
        first_is_lo = (a1 <= a2)[on]
        w_at_hi = (0.5 * (t_hi ** 2 - t_lo ** 2) - lo[on] * (t_hi - t_lo)) / L
        w_at_lo = (t_hi - t_lo) - w_at_hi
        w1 = np.where(first_is_lo, w_at_lo, w_at_hi)
        w2 = np.where(first_is_lo, w_at_hi, w_at_lo)
        nodes = np.concatenate([n1[on], n2[on]])
        w = sign * np.concatenate([w1, w2]) / (2 * half_width)
        for comp, trig in ((0, np.cos(th[nodes])), (1, np.sin(th[nodes]))):
            r.append(np.full(nodes.size, i))
            c.append(body.watch_index[comp, nodes])
            v.append(w * trig)
    return sp.csr_matrix((np.concatenate(v), (np.concatenate(r), np.concatenate(c))),
                         shape=(len(arcs.centres), nwatch))


# --------------------------------------------------------------------------------------
# The four kinds of rows
# --------------------------------------------------------------------------------------
def cam_rows(structure: Structure, geom: DriveGeometry, u_watch: np.ndarray) -> Rows:
    """Rows of the IR bore nodes against the rigid cam, linearised about ``u_watch``.

    Parameters
    ----------
    structure : Structure
        The bodies and the watch vector.
    geom : DriveGeometry
        The drive (cam of Eq. 3).
    u_watch : numpy.ndarray
        The configuration (watch vector) where gaps and normals are evaluated.

    Returns
    -------
    Rows
        Kind ``cam``, one row per IR bore node.
    """
    ir = structure.bodies["ir"]
    nodes = ir.independent(ir.body_mesh.node_sets["ir_bore"])
    X = ir.x[:, nodes]
    x = X + ir.node_displacements(nodes, u_watch)
    cp = cam_points(geom.cam_A, geom.cam_B, geom.cam_n, 32768)
    best_g, best_n = closest_on_cam(cp, x)
    k = nodes.size
    r = np.repeat(np.arange(k), 2)
    c = np.column_stack([ir.watch_index[0, nodes], ir.watch_index[1, nodes]]).ravel()
    v = best_n.T.ravel()
    G = sp.csr_matrix((v, (r, c)), shape=(k, structure.nwatch))
    g0 = best_g - G @ u_watch
    return Rows("cam", G, g0)


def ball_rows(structure: Structure, geom: DriveGeometry) -> Rows:
    """Rows of the balls: radial approach of the raceway arcs each ball acts on.

    Parameters
    ----------
    structure : Structure
        The bodies and the watch vector.
    geom : DriveGeometry
        The drive (ball count, diameter and radial clearance).

    Returns
    -------
    Rows
        Kind ``ball``, one row per ball (per ball in [0, pi) in the half model).
    """
    g = geom
    ir, orr = structure.bodies["ir"], structure.bodies["or"]
    # half model: the balls in [0, pi) (ball 0 on the cut, its image at pi implied)
    nb = g.n_balls // 2 if structure.half else g.n_balls
    per = math.pi if structure.half else 2 * math.pi
    thb = 2 * math.pi * np.arange(nb) / g.n_balls
    # each ball acts on a raceway arc of a quarter ball diameter, fixed in mm so the
    # patch stiffness does not depend on the mesh (the Hertz law adds the local part)
    hw_i = BALL_PATCH_FRAC * g.ball_dia / g.ir_race
    hw_o = BALL_PATCH_FRAC * g.ball_dia / g.or_race
    Gi = _arc_average_rows(ir, ir.body_mesh.edge_sets["ir_race"], _Arcs(thb, hw_i, per), -1.0,
                           structure.nwatch)
    Go = _arc_average_rows(orr, orr.body_mesh.edge_sets["or_race"], _Arcs(thb, hw_o, per), +1.0,
                           structure.nwatch)
    return Rows("ball", (Gi + Go).tocsr(), np.full(nb, g.ball_gap))


def fit_rows(structure: Structure, geom: DriveGeometry, n_bins: int) -> Rows:
    """Rows of the OR outer surface against the FS bore: ``n_bins`` bins over the circle.

    Parameters
    ----------
    structure : Structure
        The bodies and the watch vector.
    geom : DriveGeometry
        The drive (FS bore and OR outer radius: the fit).
    n_bins : int
        Bins over the whole circle (the half model uses those in [0, pi)).

    Returns
    -------
    Rows
        Kind ``fit``, one row per bin.
    """
    g = geom
    fs, orr = structure.bodies["fs"], structure.bodies["or"]
    # half model: the bins over [0, pi) only (same bin width)
    nbin = n_bins // 2 if structure.half else n_bins
    per = math.pi if structure.half else 2 * math.pi
    arcs = _Arcs(per * np.arange(nbin) / nbin, math.pi / n_bins, per)
    G = (_arc_average_rows(fs, fs.body_mesh.edge_sets["fs_bore"], arcs, +1.0, structure.nwatch)
         + _arc_average_rows(orr, orr.body_mesh.edge_sets["or_outer"], arcs, -1.0,
                             structure.nwatch)).tocsr()
    return Rows("fit", G, np.full(nbin, g.r_fs_bore - g.or_outer))


@dataclass(frozen=True)
class _SegmentPairs:
    """Node-to-segment pairs of one pass: normal and slip rows, gap constants, kept nodes."""
    G: sp.csr_matrix
    slip: sp.csr_matrix
    g0: np.ndarray
    kept: np.ndarray


def _node_to_segment(sb: Body, sn: np.ndarray, mb: Body, edge_set: str,
                     u_watch: np.ndarray, cand_gap: float) -> _SegmentPairs:
    """Slave nodes ``sn`` of body ``sb`` against the closest boundary segment of body
    ``mb`` (group ``edge_set``), gap along the segment's outward normal at the deformed
    configuration: normal and tangential (slip) rows d . (u_slave - u_master point) and the
    gap g0 + G u of the pairs whose gap is below ``cand_gap``."""
    nwatch = u_watch.size
    match = match_to_outline(sb, sn, mb, edge_set, u_watch)
    bg, be, bt, E, nrm = match.gap, match.segment, match.t, match.edges, match.normals
    kept = bg < cand_gap
    sn, bg, be, bt = sn[kept], bg[kept], be[kept], bt[kept]
    n = nrm[:, be]
    k = sn.size

    def pair_rows(d):
        rows, cols, vals = [], [], []
        for comp in (0, 1):
            rows += [np.arange(k)] * 3
            cols += [sb.watch_index[comp, sn], mb.watch_index[comp, E[be, 0]],
                     mb.watch_index[comp, E[be, 1]]]
            vals += [d[comp], -(1 - bt) * d[comp], -bt * d[comp]]
        return sp.csr_matrix((np.concatenate(vals),
                              (np.concatenate(rows), np.concatenate(cols))),
                             shape=(k, nwatch))

    G = pair_rows(n)
    slip = pair_rows(np.vstack([-n[1], n[0]]))   # slip along the master segment (friction)
    return _SegmentPairs(G, slip, bg - G @ u_watch, kept)


def tooth_rows(structure: Structure, geom: DriveGeometry, u_watch: np.ndarray, cand_gap: float,
               nodes: tuple[np.ndarray, np.ndarray] | None = None) -> Rows:
    """FS/CS tooth contact pairs at the deformed configuration.

    Two passes: every FS tooth-boundary node against the CS tooth segments, and the CS
    tip-land nodes (tip corners included) against the FS tooth segments: one pass alone
    would let a CS tip corner sink into an FS flank between two FS nodes.  A flank layer solved
    on the FS pass alone (``DriveGeometry.flank_layer_fs_pass_only``) has the first pass only:
    its overlap is integrated along the FS outline, which meets every overlap, and a tip corner
    sinking in is the layer's own compliance.  A node beyond
    the end of its closest segment gets its distance to the corner as its gap
    (``closest_segments``).

    Parameters
    ----------
    structure : Structure
        The bodies and the watch vector.
    geom : DriveGeometry
        The drive (tooth counts and CS tip and root radii).
    u_watch : numpy.ndarray
        The configuration where the pairs are found and linearised.
    cand_gap : float
        Pairs whose gap there is below this (mm) are kept.
    nodes : tuple of numpy.ndarray, optional
        The ``slave_nodes`` of earlier rows: the same slave nodes re-paired and
        re-linearised (same rows, new geometry).

    Returns
    -------
    Rows
        Kind ``tooth``, with slip rows, the FS tooth of every pair and its slave nodes.
    """
    fs, cs = structure.bodies["fs"], structure.bodies["cs"]
    if nodes is None:
        sn_fs = fs.independent(np.intersect1d(fs.body_mesh.node_sets["fs_teeth"], fs.watch_nodes))
        cn = np.intersect1d(cs.body_mesh.node_sets["cs_teeth"], cs.watch_nodes)
        r_cn = np.hypot(cs.x[0, cn], cs.x[1, cn])
        # a rounded tip's nodes lie within about 0.6 of its radius of the tip circle
        tip_band = geom.r_cs_tip + max(CS_TIP_BAND * (geom.r_cs_root - geom.r_cs_tip), geom.tip_round)
        sn_cs = cs.independent(cn[r_cn <= tip_band])
        if geom.flank_layer_um_per_MPa > 0 and geom.flank_layer_fs_pass_only:
            sn_cs = sn_cs[:0]
    else:
        sn_fs, sn_cs = nodes
    fs_pass = _node_to_segment(fs, sn_fs, cs, "cs_teeth", u_watch, cand_gap)
    cs_pass = _node_to_segment(cs, sn_cs, fs, "fs_teeth", u_watch, cand_gap)
    sn_fs, sn_cs = sn_fs[fs_pass.kept], sn_cs[cs_pass.kept]
    compliance = layer = None
    if geom.flank_layer_um_per_MPa > 0:
        c = 1e-3 * geom.flank_layer_um_per_MPa
        compliance = c / np.concatenate(
            [geom.face_fs * _tributary_length(fs, "fs_teeth", sn_fs),
             geom.face_cs * _tributary_length(cs, "cs_teeth", sn_cs)])
        layer = layer_edges(
            [LayerPass(fs, sn_fs, "fs_teeth", cs, "cs_teeth", c / geom.face_fs, first_row=0),
             LayerPass(cs, sn_cs, "cs_teeth", fs, "fs_teeth", c / geom.face_cs, first_row=sn_fs.size)], u_watch)
    # which FS tooth a pair belongs to (teeth in contact); the half model's tooth z/2
    # is the image of tooth 0 (ids modulo z/2; counted twice)
    zid = geom.z_fs // 2 if structure.half else geom.z_fs
    th = np.concatenate([np.arctan2(fs.x[1, sn_fs], fs.x[0, sn_fs]),
                         np.arctan2(cs.x[1, sn_cs], cs.x[0, sn_cs])])
    tooth = np.round(th / (2 * math.pi / geom.z_fs)).astype(int) % zid
    return Rows("tooth", sp.vstack([fs_pass.G, cs_pass.G]).tocsr(),
                np.concatenate([fs_pass.g0, cs_pass.g0]),
                slip=sp.vstack([fs_pass.slip, cs_pass.slip]).tocsr(), tooth=tooth,
                slave_nodes=(sn_fs, sn_cs), compliance=compliance, layer=layer)


def _tributary_length(body: Body, edge_set: str, nodes: np.ndarray) -> np.ndarray:
    """Half the length of the boundary edges of ``edge_set`` at each of ``nodes`` (mm)."""
    E = body.body_mesh.edge_sets[edge_set]
    length = np.hypot(*(body.x[:, E[:, 1]] - body.x[:, E[:, 0]]))
    per_node = np.zeros(body.x.shape[1])
    np.add.at(per_node, E[:, 0], 0.5 * length)
    np.add.at(per_node, E[:, 1], 0.5 * length)
    return per_node[nodes]
