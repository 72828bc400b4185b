"""Compliance of loads on single watched nodes, kept per body and reused by later contact rows.

A contact row loads at most two nodes of a tooth body: a slave node (its normal) or the two
ends of a master segment (weights 1 - xi, xi).  Each re-linearisation of the tooth rows (the
preload ramp, settling at +-T) moves the normal and the weights a little, which made every
changed row a new back-substitution, two thirds of a design's solve time.  The rows' node
pieces, though, keep falling on the same nodes: once a node has the responses to two
perpendicular unit loads, K^-1 of any load on it is their combination, and a row's column is
the sum of its nodes' pieces.  On hd42-lhs-16 (default half mesh, 0.157 m) that takes the
back-substitutions of a solve from 4822 columns to about 2230.

Rows spread over more nodes (the ball rows' arc averages) gain nothing from it and are
back-substituted whole, as before.  The node responses are exact columns of K^-1 (not an
approximation), so a row's column differs from its direct back-substitution by round-off.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
import scipy.sparse as sp

# the back-substitution of unit loads (node, unit direction) on the body: their responses
# (n_watch_dofs x k) and twists (k)
NodeSolve = Callable[[list[tuple[int, np.ndarray]]], tuple[np.ndarray, np.ndarray]]

# a load piece whose direction is within this (relative cross product) of a node's single known
# direction reuses it; the neglected part is that small against the piece
PARALLEL_TOL = 1e-12
# rows on up to this many nodes of a tooth body are split into node pieces (the balls' rows
# on the rings barely change between linearisations and gain nothing)
MAX_NODES_SPLIT = 2
SPLIT_BODIES = ("fs", "cs")


class NodeColumns:
    """Responses (on the body's own watch dofs, and twist) of unit loads on its single nodes.

    Parameters
    ----------
    n_watch_dofs : int
        The body's watch dofs (a load on a body moves no other body).
    """

    def __init__(self, n_watch_dofs: int):
        self._rows = np.zeros((0, n_watch_dofs))   # response j in row j (contiguous)
        self.twist = np.zeros(0)
        self.size = 0
        self.directions: dict[int, list[tuple[np.ndarray, int]]] = {}   # node -> (unit dir, j)

    def _reserve(self, k: int):
        if self.size + k > self._rows.shape[0]:
            cap = max(self._rows.shape[0] * 3 // 2, self.size + k, 256)
            grown = np.zeros((cap, self._rows.shape[1]))
            grown[:self.size] = self._rows[:self.size]
            self._rows = grown
            twist = np.zeros(cap)
            twist[:self.size] = self.twist[:self.size]
            self.twist = twist

    def plan(self, node: int, piece: np.ndarray, pending: list[tuple[int, np.ndarray]]) -> None:
        """Make ``node`` able to express ``piece``: queue a new unit direction in ``pending``
        if its known directions do not span it (the first is the piece's own direction, the
        second perpendicular to the first, so the pair is orthonormal)."""
        known = self.directions.setdefault(node, [])
        if len(known) == 2:
            return
        size = math.hypot(piece[0], piece[1])
        if not known:
            d = piece / size
        else:
            d0 = known[0][0]
            if abs(d0[0] * piece[1] - d0[1] * piece[0]) <= PARALLEL_TOL * size:
                return
            d = np.array([-d0[1], d0[0]])
        known.append((d, self.size + len(pending)))
        pending.append((node, d))

    def add(self, U_watch: np.ndarray, twist: np.ndarray) -> None:
        """Store the responses (n_watch_dofs x k) of the pending loads, in their order."""
        k = U_watch.shape[1]
        self._reserve(k)
        self._rows[self.size:self.size + k] = U_watch.T
        self.twist[self.size:self.size + k] = twist
        self.size += k

    def coefficients(self, node: int, piece: np.ndarray) -> list[tuple[int, float]]:
        """(response index, weight) whose sum is the response to ``piece`` on ``node``."""
        return [(j, float(d @ piece)) for d, j in self.directions[node]]

    def columns(self, G_body: sp.csc_matrix, solve: NodeSolve, batch: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Responses of the rows (columns of ``G_body``, the body's watch dofs x k) on at most
        ``MAX_NODES_SPLIT`` nodes, from node responses (new ones solved ``batch`` at a time).

        Returns the split columns' indices, their responses and twists, and the indices of
        the columns left to back-substitute whole.
        """
        k = G_body.shape[1]
        n_nodes = G_body.shape[0] // 2
        col = np.repeat(np.arange(k), np.diff(G_body.indptr))
        key, inv = np.unique(col * n_nodes + G_body.indices // 2, return_inverse=True)
        pieces = np.zeros((key.size, 2))
        np.add.at(pieces, (inv, G_body.indices % 2), G_body.data)
        piece_col, piece_node = key // n_nodes, key % n_nodes
        nodes_per_col = np.bincount(piece_col, minlength=k)
        split = (nodes_per_col > 0) & (nodes_per_col <= MAX_NODES_SPLIT)
        keep = split[piece_col] & pieces.any(axis=1)
        piece_col, piece_node, pieces = piece_col[keep], piece_node[keep], pieces[keep]
        pending: list[tuple[int, np.ndarray]] = []
        for n, piece in zip(piece_node.tolist(), pieces):
            self.plan(n, piece, pending)
        for c0 in range(0, len(pending), batch):
            self.add(*solve(pending[c0:c0 + batch]))
        split_cols = np.flatnonzero(split)
        position = np.cumsum(split) - 1            # column -> its place among the split ones
        r, c, v = [], [], []
        for n, j, piece in zip(piece_node.tolist(), position[piece_col].tolist(), pieces):
            for i, w in self.coefficients(n, piece):
                r.append(i)
                c.append(j)
                v.append(w)
        C = sp.csc_matrix((v, (r, c)), shape=(self.size, split_cols.size))
        X, Xq = self.combine(C)
        return split_cols, X, Xq, np.flatnonzero((nodes_per_col > MAX_NODES_SPLIT))

    def combine(self, C: sp.csc_matrix) -> tuple[np.ndarray, np.ndarray]:
        """Responses (n_watch_dofs x k) and twists (k) of the loads C (size x k) in the stored
        basis."""
        R = self._rows[:self.size]
        return np.asarray((C.T @ R).T), C.T @ self.twist[:self.size]
