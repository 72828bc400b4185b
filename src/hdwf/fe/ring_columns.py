"""Compliance columns of a toothed ring from its loads turned back to one tooth period.

The FS and the CS are meshed as one tooth period copied round (``hdwf.drive.sector_mesh``), so
their stiffness commutes with S_p, the turn of the ring by p periods (a field's values moved to
the nodes p periods on, their components turned by p periods; in the half model a node turned
past the cut at angle pi is its partner at angle 0 with u(-x) = -u(x)).  A load on the teeth of
period p therefore answers as the same load turned back by p periods, answered, and turned
forward: only loads on the node sets of the first periods are back-substituted, and the
hundreds of tooth rows of the other periods are gathers of those responses.  On HD 42's
default half mesh the FS and CS back-substitutions of a studies' solve fall from 1314 to 177.

A floating body (the FS: its rotation pinned at one dof, the rigid amplitudes extra unknowns of
the contact problem) is solved with the pinned factorisation A, which does not commute with
S_p.  A generalized inverse that does, G f = Pi A (f - W R c(f)) with c(f) = (R^T W R)^-1 R^T f
(W the nodes' unit weights, the tied cut nodes left out; Pi the W-orthogonal projection off
the rigid modes R), turns into A by
    A f = G f + X c(f) - R (E^T R)^-1 E^T G f,    X = A W R,  E the pinned dofs,
since A f and G f differ only by the response to the reaction at E and the equilibrating
W R c(f), and by a rigid motion.  So the kept responses are G f0 of the base-period loads f0,
the body's X is one more back-substitution, and S_p G f0 = G S_p f0.

Whether a body is such a ring is checked, not assumed: ``RingColumns.for_body`` maps every node
on its image one period on (within 1e-7 of the ring's size), and compares the turned response
of a load with its direct back-substitution; a
body that fails either keeps the plain ``NodeColumns``.  Written by hand: no library turns a
sparse factorisation's columns with a mesh's rotational symmetry.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from hdwf.fe.bodies import Body
from hdwf.fe.node_columns import MAX_PATTERN_NODES, plan_patterns, row_pieces

# a turned node must land on a node within this fraction of the ring's outer radius
MAP_TOL = 1e-7
# the turned response of the check load must match its back-substitution to this (relative to
# its largest value): the CS matches to 1e-13, the FS, floating and pinned at one dof, to
# 1e-9..2e-8 (HD 42, coarse and default half meshes, turns of 1 to 100 periods)
CHECK_TOL = 1e-6


class RingTurns:
    """Where every node of a ring's mesh comes from under turns by whole tooth periods.

    ``source(p)[n]`` is the node whose value the turn S_p moves to node n, ``sign(p)[n]`` is -1
    where that value crossed the half model's cut, and the components are turned by p * step.

    Parameters
    ----------
    x : numpy.ndarray
        Node coordinates (2, n), mm.
    teeth : int
        Tooth count of the ring: the turn by one period is 2 pi / teeth.
    half : bool
        Half model (nodes at angles 0..pi, u(-x) = -u(x)).
    """

    def __init__(self, x: np.ndarray, teeth: int, half: bool):
        self.step = 2.0 * math.pi / teeth
        self.periods = teeth // 2 if half else teeth
        scale = float(np.hypot(*x).max())
        c, s = math.cos(-self.step), math.sin(-self.step)
        back = np.vstack([c * x[0] - s * x[1], s * x[0] + c * x[1]])
        sign = np.ones(x.shape[1])
        if half:                                  # turned below angle 0: the partner at -x
            crossed = back[1] < -MAP_TOL * scale
            back[:, crossed] *= -1.0
            sign[crossed] = -1.0
        dist, src = cKDTree(x.T).query(back.T)
        if dist.max() > MAP_TOL * scale:
            raise ValueError(f"the mesh is not periodic with {teeth} teeth: a node turned by one "
                             f"period is {dist.max():.3g} mm from the nearest node")
        # a map for every turn is kept (a solve turns by most of them), in the narrowest types
        # that hold it: a quarter of the memory of int64 and float64 maps
        self._source = [np.arange(x.shape[1], dtype=np.int32), src.astype(np.int32)]
        self._sign = [np.ones(x.shape[1], dtype=np.int8), sign.astype(np.int8)]
        angle = np.mod(np.arctan2(x[1], x[0]), 2.0 * math.pi)
        if half:
            angle = np.where(angle > 1.5 * math.pi, 0.0, angle)   # -0.0 rounding at the cut
        # the period a node lies in (a node at the cut at pi: the last)
        self.period = np.minimum(np.floor(angle / self.step + 1e-9).astype(np.int64),
                                 self.periods - 1)

    def source(self, p: int) -> np.ndarray:
        """Node whose value S_p brings to each node."""
        self._extend(p)
        return self._source[p]

    def sign(self, p: int) -> np.ndarray:
        """-1 where S_p's value crossed the cut (half model), else 1."""
        self._extend(p)
        return self._sign[p]

    def rotation(self, p: int) -> tuple[float, float]:
        """cos and sin of the turn by p periods."""
        return math.cos(p * self.step), math.sin(p * self.step)

    def _extend(self, p: int) -> None:
        # S_p = S_1 S_(p-1): the value at n comes from src1[n] of S_(p-1)'s field
        while len(self._source) <= p:
            prev_src, prev_sign = self._source[-1], self._sign[-1]
            src1, sign1 = self._source[1], self._sign[1]
            self._source.append(prev_src[src1])
            self._sign.append(sign1 * prev_sign[src1])


class RingColumns:
    """Responses (watch dofs and twist) of loads on one or two nodes of a ring body, from loads
    turned back to their node sets' base periods.

    The interface is ``NodeColumns``'s (``columns``, ``size``); build it with ``for_body``.

    Parameters
    ----------
    body : Body
        The ring (FS or CS), factorised.
    turns : RingTurns
        Its node map under turns by periods.
    twist_response : numpy.ndarray or None
        A q (full body dofs): the FS's response to its twist measure q as a load, so that a
        load's twist q^T A f is f^T A q (A is symmetric), exactly what a prescribed twist's
        row uses; None for a body whose responses have no twist.
    """

    def __init__(self, body: Body, turns: RingTurns, twist_response: np.ndarray | None):
        self.body = body
        self.turns = turns
        nd = body.dofs
        self._twist_response = twist_response
        self._size = 0
        self.patterns: dict[tuple[int, ...], list[tuple[np.ndarray, int]]] = {}
        names = sorted(body.modes)
        self._R = np.array([body.modes[m] for m in names]).T if names else np.zeros((nd.size, 0))
        weight = np.ones(nd.shape[1])
        weight[body.tied_nodes] = 0.0
        self._w = np.zeros(nd.size)
        self._w[nd[0]], self._w[nd[1]] = weight, weight
        self._pinned = self._pinned_dofs()
        pin_at = [np.argwhere(nd == d)[0] for d in self._pinned]     # (component, node) each
        self._pin_components = np.array([c for c, _ in pin_at], dtype=np.int64)
        self._pin_nodes = np.array([n for _, n in pin_at], dtype=np.int64)
        # G f0 of every base pattern, kept only at the nodes a turn reads it from: the watch nodes
        # (a turn maps them onto each other) and the pins' sources; 2 rows a node (x, then y,
        # ``_rows``); patterns grow by doubling
        self._rows = self._kept_rows()
        self._responses = np.zeros((int((self._rows >= 0).sum()), 0))
        if self._R.shape[1]:
            WR = self._w[:, None] * self._R
            self._RWR_inv = np.linalg.inv(self._R.T @ WR)
            self._X = body.solve(WR)
            self._ER_inv = np.linalg.inv(self._R[self._pinned])     # (E^T R)^-1

    @classmethod
    def for_body(cls, body: Body, teeth: int, half: bool,
                 twist_response: np.ndarray | None) -> "RingColumns | None":
        """The ring columns of ``body`` if it is a ring of ``teeth`` periods, else None."""
        try:
            turns = RingTurns(body.x, teeth, half)
        except ValueError:
            return None
        ring = cls(body, turns, twist_response)
        return ring if ring._checks() else None

    @property
    def size(self) -> int:
        """Responses back-substituted and kept."""
        return self._size

    # ------------------------------------------------------------------ the algebra

    def _pinned_dofs(self) -> np.ndarray:
        """Body dofs held at zero by the factorisation as rigid-mode pins (floating body)."""
        if not self.body.modes:
            return np.zeros(0, dtype=np.int64)
        b = self.body
        n_reduced = b.tie.shape[1] if b.tie is not None else b.stiffness.shape[0]
        pinned_reduced = np.setdiff1d(np.arange(n_reduced), b.free_dofs)
        if b.tie is None:
            return pinned_reduced
        # a pin sits on an interior node: one body dof maps onto it with weight 1
        tie = b.tie.tocsc()
        return np.array([tie.indices[tie.indptr[j]] for j in pinned_reduced])

    def _kept_rows(self) -> np.ndarray:
        """Row of the kept responses for each (component, node), -1 where none is kept (2, n).

        A turn reads a watch node's value from another watch node when the watch nodes are the
        same on every period (every tooth watched); otherwise every node is kept."""
        n = self.body.dofs.shape[1]
        wn = self.body.watch_nodes
        kept = np.zeros(n, dtype=bool)
        kept[wn] = True
        if not kept[self.turns.source(1)[wn]].all():
            kept[:] = True
        for p in range(self.turns.periods):
            kept[self.turns.source(p)[self._pin_nodes]] = True
        nodes = np.flatnonzero(kept)
        rows = np.full((2, n), -1, dtype=np.int64)
        rows[0, nodes] = 2 * np.arange(nodes.size)
        rows[1, nodes] = rows[0, nodes] + 1
        return rows

    def _generalized(self, F: np.ndarray) -> np.ndarray:
        """G F: the response that commutes with the turns (A F for a body without modes)."""
        if not self._R.shape[1]:
            return self.body.solve(F)
        c = self._RWR_inv @ (self._R.T @ F)
        U = self.body.solve(F) - self._X @ c
        return U - self._R @ (self._RWR_inv @ (self._R.T @ (self._w[:, None] * U)))

    def _turn(self, U: np.ndarray, p: int, nodes: np.ndarray, cols: np.ndarray | None = None,
              right: np.ndarray | None = None, kept: bool = False) -> np.ndarray:
        """(S_p U) at ``nodes`` (n), x then y: (2, n) or (2, n, k); of U's columns ``cols`` only
        if given (gathered without copying the rest), times ``right`` if given (the turn acts
        node by node, so it commutes with combining columns: the fewer combined ones are turned).
        U holds body dofs, or with ``kept`` the kept responses' rows (``_kept_rows``)."""
        src, sgn = self.turns.source(p)[nodes], self.turns.sign(p)[nodes]
        nd = self._rows if kept else self.body.dofs
        if cols is None:
            ux, uy = U[nd[0, src]], U[nd[1, src]]
        else:
            ux, uy = U[np.ix_(nd[0, src], cols)], U[np.ix_(nd[1, src], cols)]
        if right is not None:
            ux, uy = ux @ right, uy @ right
        c, s = self.turns.rotation(p)
        sg = sgn.reshape((-1,) + (1,) * (ux.ndim - 1))
        return np.stack([sg * (c * ux - s * uy), sg * (s * ux + c * uy)])

    def _pinned_correction(self, at_pins: np.ndarray, modes_load: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients of X and of R that make G's response A's, from (G f)_E and R^T f:
        c(f) = (R^T W R)^-1 R^T f and -(E^T R)^-1 (G f)_E."""
        return self._RWR_inv @ modes_load, -self._ER_inv @ at_pins

    def _checks(self) -> bool:
        """The turned response of a test load is its back-substitution."""
        b = self.body
        rng = np.random.default_rng(0)
        candidates = b.independent(b.watch_nodes)
        nodes = np.sort(rng.choice(candidates, size=min(3, candidates.size), replace=False))
        load = rng.standard_normal((2, nodes.size))
        F0 = np.zeros((b.stiffness.shape[0], 1))
        F0[b.dofs[0, nodes], 0], F0[b.dofs[1, nodes], 0] = load
        p = max(1, self.turns.periods // 3)
        F_turned = np.zeros_like(F0)
        all_nodes = np.arange(b.dofs.shape[1])
        turned = self._turn(F0, p, all_nodes)[:, :, 0]
        if b.tie is not None:     # a load on a tied node acts on its partner: fold it once
            turned[:, b.tied_nodes] = 0.0
        F_turned[b.dofs[0], 0], F_turned[b.dofs[1], 0] = turned
        direct = b.solve(F_turned)[:, 0]
        U = self._turn(self._generalized(F0), p, all_nodes)[:, :, 0]
        via = np.zeros_like(direct)
        via[b.dofs[0]], via[b.dofs[1]] = U
        if self._R.shape[1]:
            c, g = self._pinned_correction(via[self._pinned], self._R.T @ F_turned[:, 0])
            via = via + self._X @ c + self._R @ g
        ok = np.abs(via - direct).max() <= CHECK_TOL * np.abs(direct).max()
        return bool(ok)

    # ------------------------------------------------------------------ the columns

    def columns(self, G_body: sp.csc_matrix, solve: object = None, batch: int = 16
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """As ``NodeColumns.columns``: the rows on at most ``MAX_PATTERN_NODES`` nodes (their
        indices, responses on the body's watch dofs and twists) and the rows left to
        back-substitute whole.  ``solve`` is not used: a base pattern's response is G f0 on
        the whole body (``batch`` at a time), which only this class can turn."""
        piece_node, pieces, nodes_per_col, start = row_pieces(G_body)
        wn = self.body.watch_nodes
        nd = self.body.dofs
        pending: list[tuple[np.ndarray, np.ndarray]] = []
        built, periods, loads_dofs, loads_vals, coefs = [], [], [], [], []
        whole = list(np.flatnonzero(nodes_per_col > MAX_PATTERN_NODES))
        for col in np.flatnonzero((nodes_per_col > 0) & (nodes_per_col <= MAX_PATTERN_NODES)):
            a, b = start[col], start[col + 1]
            nodes = wn[piece_node[a:b]]
            load = pieces[a:b]
            p = int(self.turns.period[nodes[0]])
            src, sgn = self.turns.source(p)[nodes], self.turns.sign(p)[nodes]
            if np.unique(src).size < src.size:       # two nodes of a tied pair: no base set
                whole.append(col)
                continue
            c, s = self.turns.rotation(p)             # the load turned back by p periods
            base = sgn[:, None] * np.column_stack([c * load[:, 0] + s * load[:, 1],
                                                   -s * load[:, 0] + c * load[:, 1]])
            order = np.argsort(src)
            coefs.append(plan_patterns(self.patterns, self.size,
                                       tuple(src[order].tolist()), base[order].ravel(), pending))
            built.append(col)
            periods.append(p)
            loads_dofs.append(np.stack([nd[0, nodes], nd[1, nodes]], axis=1).ravel())
            loads_vals.append(load.ravel())
        for c0 in range(0, len(pending), batch):
            self._add(pending[c0:c0 + batch])
        X = np.zeros((2 * wn.size, len(built)))
        Xq = np.zeros(len(built))
        periods_arr = np.array(periods, dtype=np.int64)
        for p in np.unique(periods_arr).tolist():
            js = np.flatnonzero(periods_arr == p)
            X[:, js], Xq[js] = self._turned_responses(p, [coefs[j] for j in js],
                                                      [loads_dofs[j] for j in js],
                                                      [loads_vals[j] for j in js])
        return (np.array(built, dtype=np.int64), X, Xq,
                np.array(sorted(whole), dtype=np.int64))

    def _add(self, loads: list[tuple[np.ndarray, np.ndarray]]) -> None:
        """Back-substitute the base patterns ``loads`` (dofs 2 node + component, values)."""
        b = self.body
        F = np.zeros((b.stiffness.shape[0], len(loads)))
        for j, (dofs, values) in enumerate(loads):
            F[b.dofs[dofs % 2, dofs // 2], j] = values
        full = self._generalized(F)
        U = np.empty((self._responses.shape[0], full.shape[1]))
        kept = self._rows[0] >= 0
        U[self._rows[0, kept]], U[self._rows[1, kept]] = full[b.dofs[0, kept]], full[b.dofs[1, kept]]
        if self._size + U.shape[1] > self._responses.shape[1]:
            grown = np.zeros((U.shape[0], max(2 * self._responses.shape[1], self._size + U.shape[1], 64)))
            grown[:, :self._size] = self._responses[:, :self._size]
            self._responses = grown
        self._responses[:, self._size:self._size + U.shape[1]] = U
        self._size += U.shape[1]

    def _turned_responses(self, p: int, coefs: list[list[tuple[int, float]]],
                          loads_dofs: list[np.ndarray], loads_vals: list[np.ndarray]
                          ) -> tuple[np.ndarray, np.ndarray]:
        """Watch responses (2 n_watch x k) and twists of k rows of period p, A f_p."""
        used = np.array(sorted({i for coef in coefs for i, _ in coef}), dtype=np.int64)
        where = {i: n for n, i in enumerate(used.tolist())}
        C = np.zeros((len(used), len(coefs)))
        for j, coef in enumerate(coefs):
            for i, w in coef:
                C[where[i], j] += w
        wn = self.body.watch_nodes
        turned = self._turn(self._responses, p, wn, used, right=C, kept=True)    # (2, n_watch, k)
        Uw = np.empty((2 * wn.size, len(coefs)))
        Uw[0::2], Uw[1::2] = turned[0], turned[1]
        twist = np.zeros(len(coefs))
        if self._twist_response is not None:
            twist = np.array([self._twist_response[d] @ v for d, v in zip(loads_dofs, loads_vals)])
        if self._R.shape[1]:
            nd = self.body.dofs
            at_pins = self._turn(self._responses, p, self._pin_nodes, used, right=C, kept=True)   # (2, pins, k)
            pins_val = at_pins[self._pin_components, np.arange(self._pinned.size)]
            Rt = np.zeros((self._R.shape[1], len(coefs)))
            for j, (dofs, vals) in enumerate(zip(loads_dofs, loads_vals)):
                Rt[:, j] = self._R[dofs].T @ vals
            c, g = self._pinned_correction(pins_val, Rt)
            watch_rows = np.stack([nd[0, wn], nd[1, wn]], axis=1).ravel()
            Uw += self._X[watch_rows] @ c + self._R[watch_rows] @ g
        return Uw, twist
