"""Compliance of loads on one or two nodes of a tooth body, kept and reused by later rows.

A contact row loads at most two nodes of a tooth body: a slave node (along its normal) or the
two ends of a master segment (weights 1 - xi, xi).  Each re-linearisation of the tooth rows
(the preload ramp, settling at +-T) turns the normal and moves the weights a little, and every
changed row used to be a new back-substitution: two thirds of a heavily loaded design's solve.
Yet the rows keep falling on the same nodes, and a node pair has only four dofs.  So every
load this module back-substitutes is kept as a *pattern* on its node set, with its response;
a new row on nodes S is first projected on the patterns of S and of S's single nodes, and only
the part outside their span (if larger than ``SPAN_TOL`` of the row) is a new pattern, stored
normalised.  A row on a node set seen for the first time costs one back-substitution, as
before; a node pair needs at most four.  On hd42-lhs-16 (default half mesh, 0.157 m) the FS
and CS columns of a solve fall from 4281 to about 1680.

The responses are exact columns of K^-1 and a row's column is an exact combination of them (up
to ``SPAN_TOL`` of the row), so it differs from its direct back-substitution by round-off.
Rows spread over more nodes (the ball rows' arc averages) are back-substituted whole.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import scipy.sparse as sp

from hdwf.fe.column_store import ColumnStore

# loads (dofs of the body's watch vector, values) to back-substitute: their responses
# (n_watch_dofs x k) and twists (k)
PatternSolve = Callable[[list[tuple[np.ndarray, np.ndarray]]], tuple[np.ndarray, np.ndarray]]

# a row whose part outside the known patterns' span is below this fraction of its norm is taken
# as in the span; the neglected part is that small against the row
SPAN_TOL = 1e-10
# rows on up to this many nodes of a tooth body are built from patterns (the balls' rows on
# the rings are arc averages over many nodes and barely change between linearisations)
MAX_PATTERN_NODES = 2
PATTERN_BODIES = ("fs", "cs")


class NodeColumns:
    """Responses (on the body's own watch dofs, and twist) of loads on one or two of its nodes.

    Parameters
    ----------
    n_watch_dofs : int
        The body's watch dofs (a load on a body moves no other body).
    """

    def __init__(self, n_watch_dofs: int):
        self._store = ColumnStore(n_watch_dofs + 1)   # a response, then its twist, per row
        # node set (sorted tuple) -> its patterns: (dofs of that set, unit vector, response index)
        self.patterns: dict[tuple[int, ...], list[tuple[np.ndarray, int]]] = {}

    @property
    def size(self) -> int:
        """Responses stored."""
        return self._store.size

    def plan(self, nodes: tuple[int, ...], load: np.ndarray,
             pending: list[tuple[np.ndarray, np.ndarray]]) -> list[tuple[int, float]]:
        """(response index, weight) pairs whose sum is the response to ``load``
        (``plan_patterns`` on this body's patterns)."""
        return plan_patterns(self.patterns, self.size, nodes, load, pending)

    def add(self, U_watch: np.ndarray, twist: np.ndarray) -> None:
        """Store the responses (n_watch_dofs x k) of the pending loads, in their order."""
        self._store.append(np.vstack([U_watch, twist[None, :]]))

    def columns(self, G_body: sp.csc_matrix, solve: PatternSolve, batch: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Responses of the rows (columns of ``G_body``, the body's watch dofs x k) on at most
        ``MAX_PATTERN_NODES`` nodes, from patterns (new ones solved ``batch`` at a time).

        Returns the indices of those columns, their responses and twists, and the indices of
        the columns left to back-substitute whole.
        """
        piece_node, pieces, nodes_per_col, start = row_pieces(G_body)
        built = np.flatnonzero((nodes_per_col > 0) & (nodes_per_col <= MAX_PATTERN_NODES))
        pending: list[tuple[np.ndarray, np.ndarray]] = []
        r, c, v = [], [], []
        for j, col_k in enumerate(built.tolist()):
            a, b = start[col_k], start[col_k + 1]
            for i, w in self.plan(tuple(piece_node[a:b].tolist()), pieces[a:b].ravel(), pending):
                r.append(i)
                c.append(j)
                v.append(w)
        for c0 in range(0, len(pending), batch):
            self.add(*solve(pending[c0:c0 + batch]))
        C = sp.csc_matrix((v, (r, c)), shape=(self.size, built.size))
        X, Xq = self.combine(C)
        return built, X, Xq, np.flatnonzero(nodes_per_col > MAX_PATTERN_NODES)

    def combine(self, C: sp.csc_matrix) -> tuple[np.ndarray, np.ndarray]:
        """Responses (n_watch_dofs x k) and twists (k) of the loads C (size x k) in the stored
        basis."""
        both = self._store.right_multiply(C)
        return both[:-1], both[-1]


def row_pieces(G_body: sp.csc_matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The loads of the rows (columns of ``G_body``, the body's watch dofs x k) node by node.

    Returns the watch node of every piece, its x and y load (pieces x 2), the nodes of every
    row and where each row's pieces start (k + 1; the pieces are in row order, nodes sorted).
    """
    k = G_body.shape[1]
    n_nodes = G_body.shape[0] // 2
    col = np.repeat(np.arange(k), np.diff(G_body.indptr))
    key, inv = np.unique(col * n_nodes + G_body.indices // 2, return_inverse=True)
    pieces = np.zeros((key.size, 2))
    np.add.at(pieces, (inv, G_body.indices % 2), G_body.data)
    piece_col, piece_node = key // n_nodes, key % n_nodes
    nonzero = pieces.any(axis=1)
    piece_col, piece_node, pieces = piece_col[nonzero], piece_node[nonzero], pieces[nonzero]
    nodes_per_col = np.bincount(piece_col, minlength=k)
    return piece_node, pieces, nodes_per_col, np.concatenate([[0], np.cumsum(nodes_per_col)])


def plan_patterns(patterns: dict[tuple[int, ...], list[tuple[np.ndarray, int]]], size: int,
                  nodes: tuple[int, ...], load: np.ndarray,
                  pending: list[tuple[np.ndarray, np.ndarray]]) -> list[tuple[int, float]]:
    """(response index, weight) pairs whose sum is the response to ``load``.

    ``load`` holds the x and y components on each of ``nodes`` (sorted).  Its part outside
    the span of the known ``patterns`` on ``nodes`` and on each single one of them becomes a
    new pattern (index ``size`` + its place in ``pending``), queued in ``pending`` as (dofs
    2 node + component, values) for back-substitution.
    """
    subsets = [nodes] if len(nodes) == 1 else [(n,) for n in nodes] + [nodes]
    basis, index = [], []
    for sub in subsets:
        where = [2 * nodes.index(n) + k for n in sub for k in (0, 1)]
        for vec, j in patterns.get(sub, ()):
            col = np.zeros(load.size)
            col[where] = vec
            basis.append(col)
            index.append(j)
    norm = float(np.linalg.norm(load))
    coef: list[tuple[int, float]] = []
    rest = load
    if basis:
        A = np.array(basis).T
        c = np.linalg.lstsq(A, load, rcond=None)[0]
        coef = list(zip(index, c.tolist()))
        rest = load - A @ c
    rest_size = float(np.linalg.norm(rest))
    if rest_size > SPAN_TOL * norm:
        j = size + len(pending)
        patterns.setdefault(nodes, []).append((rest / rest_size, j))
        dofs = np.array([2 * n + k for n in nodes for k in (0, 1)])
        pending.append((dofs, rest / rest_size))
        coef.append((j, rest_size))
    return coef
