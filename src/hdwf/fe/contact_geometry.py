"""Closest points and outward normals on the contact surfaces (cam curve, tooth boundaries).

Pure geometry for ``contact_rows``: the gap of a point to the rigid cam polygon, the
outward normals of a body's boundary edges, and the closest boundary segment of a point with
the corner rule: a node beyond the end of its closest segment measures its distance to that
corner (its offset along the segment's normal is the gap to the segment's straight extension).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

if TYPE_CHECKING:
    from hdwf.fe.bodies import Body


def closest_on_cam(cp: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed gap and outward normal of points to a closed counter-clockwise polygon.

    Parameters
    ----------
    cp : numpy.ndarray
        (m, 2) vertices of the polygon (the cam curve, densely sampled).
    x : numpy.ndarray
        (2, n) points.

    Returns
    -------
    gap : numpy.ndarray
        Signed distance of every point along the normal of its closest polygon edge.
    normal : numpy.ndarray
        (2, n) outward unit normal of that edge.
    """
    tree = cKDTree(cp)
    _, j = tree.query(x.T)
    best_g = np.full(x.shape[1], np.inf)
    best_n = np.zeros((2, x.shape[1]))
    nc = cp.shape[0]
    for j0, j1 in ((j - 1, j), (j, j + 1)):
        a, b = cp[j0 % nc].T, cp[j1 % nc].T
        d = b - a
        L2 = (d ** 2).sum(0)
        t = np.clip(((x - a) * d).sum(0) / L2, 0, 1)
        proj = a + t * d
        n = np.vstack([d[1], -d[0]]) / np.sqrt(L2)       # outward for a CCW curve
        gap = ((x - proj) * n).sum(0)
        dist = np.hypot(*(x - proj))
        better = dist < np.abs(best_g)
        best_g = np.where(better, gap, best_g)
        best_n = np.where(better, n, best_n)
    return best_g, best_n


def boundary_edge_normals(mesh, edges: np.ndarray) -> np.ndarray:
    """Unit normals of boundary edges pointing out of the body's material.

    Parameters
    ----------
    mesh : skfem.MeshTri
        The body mesh.
    edges : numpy.ndarray
        (k, 2) node ids of boundary edges (a contact group).

    Returns
    -------
    numpy.ndarray
        (2, k) outward unit normals.
    """
    p = mesh.p
    N = p.shape[1]
    key_f = np.sort(mesh.facets, axis=0).astype(np.int64)   # int64: N^2 overflows int32
    keys = key_f[0] * N + key_f[1]
    order = np.argsort(keys)
    e = np.sort(edges, axis=1).astype(np.int64)
    want = e[:, 0] * N + e[:, 1]
    loc = np.minimum(np.searchsorted(keys[order], want), keys.size - 1)
    pos = order[loc]
    if np.any(keys[pos] != want) or np.any(edges < 0):
        raise ValueError("boundary edges of a contact group are not edges of the "
                         "triangle mesh (gmsh mesh defect)")
    tri = mesh.f2t[0, pos]
    third = mesh.t[:, tri]
    third = np.where((third != e[:, 0]) & (third != e[:, 1]), third, -1).max(axis=0)
    d = p[:, edges[:, 1]] - p[:, edges[:, 0]]
    n = np.vstack([d[1], -d[0]]) / np.linalg.norm(d, axis=0)
    inward = np.einsum("ij,ij->j", n, p[:, third] - p[:, edges[:, 0]]) > 0
    n[:, inward] *= -1
    return n


def closest_segments(xs: np.ndarray, xa: np.ndarray, xb: np.ndarray, nrm: np.ndarray):
    """The closest of a set of segments for each point, and the gap to it.

    The gap is the offset along the segment's normal, except for a point beyond the end of
    its closest segment: that point faces a corner, and its gap is its distance to the
    corner (the normal offset there is the gap to the segment's straight extension).

    Parameters
    ----------
    xs : numpy.ndarray
        (2, n) points.
    xa, xb : numpy.ndarray
        (2, m) segment ends a -> b.
    nrm : numpy.ndarray
        (2, m) outward unit normals of the segments.

    Returns
    -------
    gap : numpy.ndarray
        Signed gap of every point (negative: penetration).
    segment : numpy.ndarray
        Index of its closest segment.
    t : numpy.ndarray
        Parameter in [0, 1] of the closest point on that segment.
    """
    tree = cKDTree((0.5 * (xa + xb)).T)
    kq = min(8, xa.shape[1])
    _, cand = tree.query(xs.T, k=kq)
    cand = cand.reshape(xs.shape[1], kq)
    n = xs.shape[1]
    best = np.full(n, np.inf)
    bg, bt = np.zeros(n), np.zeros(n)
    be = np.zeros(n, dtype=np.int64)
    front = np.full(n, -np.inf)     # largest normal offset among the closest segments
    for jj in range(kq):
        e = cand[:, jj]
        a, b = xa[:, e], xb[:, e]
        d = b - a
        t_free = ((xs - a) * d).sum(0) / (d ** 2).sum(0)
        t = np.clip(t_free, 0, 1)
        pr = a + t * d
        dist = np.hypot(*(xs - pr))
        offset = ((xs - pr) * nrm[:, e]).sum(0)
        # beyond the segment's end: the point faces a corner (the vertex), gap = distance
        beyond = (t_free < -1e-9) | (t_free > 1 + 1e-9)
        gap = np.where(beyond, dist, offset)
        tie = np.abs(dist - best) <= 1e-12
        better = (dist < best) & ~tie
        front = np.where(better, offset, np.where(tie, np.maximum(front, offset), front))
        best = np.where(better, dist, best)
        bg, be, bt = (np.where(better, gap, bg), np.where(better, e, be),
                      np.where(better, t, bt))
    # ... outside the body if it lies in front of one of the two segments that meet there
    # (the fan of a convex corner); behind both, it has sunk in at a concave vertex (the
    # internal gear's flanks are concave polylines): a penetration of that distance
    inside = (bg > 0) & (front < 0)
    return np.where(inside, -bg, bg), be, bt


@dataclass(frozen=True)
class OutlineMatch:
    """Nodes matched to the closest segment of another body's deformed outline."""
    gap: np.ndarray          # (n,) signed gap (mm; negative: penetration)
    segment: np.ndarray      # (n,) index into ``edges``
    t: np.ndarray            # (n,) parameter of the closest point on it
    edges: np.ndarray        # (m, 2) the watched outline edges (node ids of the master body)
    normals: np.ndarray      # (2, m) their outward unit normals


def match_to_outline(sb: "Body", nodes: np.ndarray, mb: "Body", edge_set: str,
                     u_watch: np.ndarray) -> OutlineMatch:
    """``nodes`` of body ``sb`` against the watched ``edge_set`` segments of body ``mb``, both
    at the displacement ``u_watch`` (``closest_segments``)."""
    xs = sb.x[:, nodes] + sb.node_displacements(nodes, u_watch)
    E = mb.body_mesh.edge_sets[edge_set]
    E = E[(mb.watch_index[0, E[:, 0]] >= 0) & (mb.watch_index[0, E[:, 1]] >= 0)]
    nrm = boundary_edge_normals(mb.body_mesh.mesh, E)
    xa = mb.x[:, E[:, 0]] + mb.node_displacements(E[:, 0], u_watch)
    xb = mb.x[:, E[:, 1]] + mb.node_displacements(E[:, 1], u_watch)
    gap, seg, t = closest_segments(xs, xa, xb, nrm)
    return OutlineMatch(gap, seg, t, E, nrm)
