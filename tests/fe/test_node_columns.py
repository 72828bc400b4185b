"""Compliance columns summed from node responses equal the direct back-substitution."""

from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from hdwf.drive.geometry import drive_geometry
from hdwf.drive.mesh import build_mesh
from hdwf.fe import LostMotionModel
from hdwf.fe.bodies import Body
from hdwf.fe.model import ZONE_DEG


@lru_cache(maxsize=None)
def _structure(symmetry="half", rings=False, zone_deg=ZONE_DEG):
    """A coarse HD 42 structure, its teeth watched within ``zone_deg`` of the major axes; with
    ``rings`` False its tooth bodies keep plain ``NodeColumns`` (no turns by periods)."""
    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.005, 0.005)
    mesh = build_mesh(g, elements_over_height=6, elements_over_thickness=4, symmetry=symmetry)
    structure = LostMotionModel(g, mesh, zone_deg=zone_deg).structure
    if not rings:
        structure.plain_node_columns()
    return structure


def _direct(structure, G):
    """K^-1 G^T restricted to the watch vector, and its twist: one solve per body, no reuse."""
    X = np.zeros((structure.nwatch, G.shape[0]))
    Xq = np.zeros(G.shape[0])
    for name, b in structure.bodies.items():
        U = b.solve(structure.watch_to_body(name, G.T.tocsc()))
        wn = b.watch_nodes
        X[b.watch_index[0, wn]] += U[b.dofs[0, wn]]
        X[b.watch_index[1, wn]] += U[b.dofs[1, wn]]
        if name == "fs":
            Xq += structure.twist_measure @ U
    return X, Xq


def _rows(structure, angle, xi):
    """Rows shaped like the contact rows: a slave node on the FS along a normal at ``angle``, a
    CS master segment (weights 1 - xi, xi) along minus that normal, the same two rows again
    (negated), and an arc average over five OR nodes (back-substituted whole)."""
    fs, cs, ring = (structure.bodies[n] for n in ("fs", "cs", "or"))
    n = np.array([np.cos(angle), np.sin(angle)])
    r, c, v = [], [], []
    for row, (body, nodes, weights) in enumerate([(fs, [3], [1.0]), (cs, [10, 11], [xi - 1, -xi]),
                                                  (fs, [3], [-1.0]), (cs, [10, 11], [1 - xi, xi]),
                                                  (ring, [0, 1, 2, 3, 4], [0.2] * 5)]):
        for node, w in zip(nodes, weights):
            for k in (0, 1):
                r.append(row)
                c.append(body.watch_offset + 2 * node + k)
                v.append(w * n[k])
    return sp.csr_matrix((v, (r, c)), shape=(5, structure.nwatch))


def test_node_patterns_reproduce_direct_columns_and_are_reused(monkeypatch):
    """A linear identity: K^-1 of a row is the combination of K^-1 of the patterns kept for its
    nodes, so the columns agree with one back-substitution per row to round-off, for the row a
    pair first had and for re-linearised ones (normal turned, weights moved).  Only a row outside
    the span of its nodes' patterns solves: a single node's span is full after two directions,
    a node pair's after four patterns."""
    structure = _structure()
    solved = []      # columns of each back-substitution compliance_columns makes
    original = Body.solve
    monkeypatch.setattr(Body, "solve", lambda self, F: solved.append(F.shape[1]) or original(self, F))
    sequence = [(0.4, 0.3), (0.4 + 1e-3, 0.3), (2.0, 0.3), (2.0, 0.6), (1.0, 0.6), (2.5, 0.45)]
    results = [(G, *structure.compliance_columns(G))
               for G in (_rows(structure, angle, xi) for angle, xi in sequence)]
    monkeypatch.undo()
    for G, X, Xq in results:
        Xd, Xqd = _direct(structure, G)
        assert np.abs(X - Xd).max() <= 1e-10 * np.abs(Xd).max()
        assert np.abs(Xq - Xqd).max() <= 1e-10 * np.abs(Xqd).max()
    # one column a body a solve (the FS, the CS pair, then the OR's whole row): new rows; the
    # normal turned by 1 mrad (both new); a third normal (the FS node's and the pair's spans hold
    # it); new weights (the pair's third pattern); new weights and normal (its fourth); then
    # anything on these nodes is in their span
    assert solved == [1, 1, 1] + [1, 1, 1] + [1] + [1, 1] + [1, 1] + [1]
