"""The four bodies seen through the watch vector: torque load, twist measure, compliance columns.

The contact problem only ever needs the displacement of contact nodes, so every body's
contact-node dofs are numbered into one *watch vector* (``u_watch``), and the contact rows
(``contact_rows``) are sparse rows over it.  ``Structure`` owns that numbering and maps
between the watch vector and the full bodies: compliance columns K^-1 G^T of contact rows
(one back-substitution per body), the rigid-mode matrix R on the watch dofs, and the full
displacement fields at a solved level.

Load and twist: the torque is a body-force pattern f = T w_i (-y, x) / sum(w r^2) on the FS
rim below the tooth roots (w_i = nodal areas), the 2D stand-in for the shear flow the cup
brings in; the twist is the work-conjugate mean rotation q^T u of the same region (exact
rigid rotation for a rigid motion).  In the half model the half rim carries T/2
(``f_scale``) while the twist measure stays the mean rotation of the rim, so the twist
equals the full model's.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from hdwf.fe.bodies import Body
from hdwf.fe.node_columns import PATTERN_BODIES, NodeColumns
from hdwf.fe.ring_columns import RingColumns

ToothColumns = NodeColumns | RingColumns

ModeName = tuple[str, str]      # (body, mode), e.g. ("fs", "rot")

# Columns per back-substitution: a multi-column Cholesky solve is fastest per column when the
# block stays in cache (FS of HD 42, default half mesh: 4.5 ms for one column, 2.0 ms a column at 8
# and 16, 2.3 at 64; benchmarks/bench_factor.py)
SOLVE_BATCH = 16


@dataclass(frozen=True)
class RigidModes:
    """The free rigid modes of a stage, restricted to what the contact problem needs."""
    watch: np.ndarray    # R: (nwatch, nmodes) each mode on the watch dofs
    twist: np.ndarray    # q^T v of each mode (twist per unit amplitude)
    load: np.ndarray     # R^T f per unit torque (f_scale q^T v)


def _number_watch_dofs(bodies: dict[str, Body]) -> int:
    """Give every body its block of the watch vector (two entries per watched node)."""
    ofs = 0
    for b in bodies.values():
        b.watch_offset = ofs
        b.watch_index = -np.ones((2, b.x.shape[1]), dtype=np.int64)
        n = b.watch_nodes.size
        b.watch_index[0, b.watch_nodes] = ofs + 2 * np.arange(n)
        b.watch_index[1, b.watch_nodes] = ofs + 2 * np.arange(n) + 1
        ofs += 2 * n
    return ofs


def _rim_twist_measure(fs: Body, r_root: float) -> np.ndarray:
    """q: the mean rotation q^T u of the FS rim below the tooth roots (area-weighted)."""
    p = fs.x
    t = fs.body_mesh.mesh.t
    rim_tri = np.hypot(*p[:, t].mean(axis=1)) < r_root
    sub = t[:, rim_tri]
    a = 0.5 * np.abs((p[0, sub[1]] - p[0, sub[0]]) * (p[1, sub[2]] - p[1, sub[0]])
                     - (p[0, sub[2]] - p[0, sub[0]]) * (p[1, sub[1]] - p[1, sub[0]]))
    w = np.zeros(p.shape[1])
    for k in range(3):
        np.add.at(w, sub[k], a / 3)
    J = float(np.sum(w * (p[0] ** 2 + p[1] ** 2)))
    q = np.zeros(fs.stiffness.shape[0])
    q[fs.dofs[0]], q[fs.dofs[1]] = -w * p[1] / J, w * p[0] / J
    return q


class Structure:
    """The factorised bodies, the watch vector and the torque load of the FS rim.

    Parameters
    ----------
    bodies : dict[str, Body]
        ``fs``, ``cs``, ``ir``, ``or`` in that order (their watch positions are numbered here).
    half : bool
        Half model (the rim carries half the torque).
    r_rim : float
        Radius (mm) below which FS triangles belong to the loaded rim (the tooth roots).
    teeth : dict[str, int], optional
        Tooth counts of the ring bodies (``fs``, ``cs``): their node responses are then turned
        from one period's (``RingColumns``) where the body checks out as such a ring.
    """

    def __init__(self, bodies: dict[str, Body], half: bool, r_rim: float,
                 teeth: dict[str, int] | None = None):
        self.bodies = bodies
        self.half = half
        self.f_scale = 0.5 if half else 1.0
        self.nwatch = _number_watch_dofs(bodies)
        self.teeth = dict(teeth or {})
        self._node_cache: dict[str, ToothColumns] = {}    # shared by copies with the same body
        self.n_dofs = sum(b.stiffness.shape[0] for b in bodies.values())
        fs = bodies["fs"]
        # load per unit torque is f_scale * twist_measure (N/(N mm))
        self.twist_measure = _rim_twist_measure(fs, r_rim)
        self.unit_torque_u = self.f_scale * fs.solve(self.twist_measure[:, None])[:, 0]
        self.unit_torque_u_watch = self.watch_vector("fs", self.unit_torque_u)
        self.unit_torque_twist = float(self.twist_measure @ self.unit_torque_u)

    def with_body(self, name: str, body: Body) -> "Structure":
        """A copy with body ``name`` replaced (same watch numbering, same torque load)."""
        new = copy.copy(self)
        new.bodies = {**self.bodies, name: body}
        # a body with the same factorisation (only scaled) has the same node responses
        new._node_cache = {n: c for n, c in self._node_cache.items()
                           if n != name or body.factor is self.bodies[name].factor}
        return new

    def watch_vector(self, name: str, u_full: np.ndarray) -> np.ndarray:
        """The watch vector holding body ``name``'s full dof vector ``u_full`` (zero elsewhere)."""
        b = self.bodies[name]
        v = np.zeros(self.nwatch)
        wn = b.watch_nodes
        v[b.watch_index[0, wn]] = u_full[b.dofs[0, wn]]
        v[b.watch_index[1, wn]] = u_full[b.dofs[1, wn]]
        return v

    def watch_to_body(self, name: str, Gt: sp.csc_matrix) -> np.ndarray:
        """Map watch-vector force columns (nwatch x k) to full-body force vectors."""
        b = self.bodies[name]
        wn = b.watch_nodes
        F = np.zeros((b.stiffness.shape[0], Gt.shape[1]))
        Gd = Gt.toarray()
        F[b.dofs[0, wn]] = Gd[b.watch_index[0, wn]]
        F[b.dofs[1, wn]] = Gd[b.watch_index[1, wn]]
        return F

    def compliance_columns(self, Grows: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
        """K^-1 G^T for rows G (k x nwatch): its watch restriction and its twist q^T K^-1 G^T.

        A row's part on one or two nodes of a tooth body is combined from the responses kept
        for those nodes (``NodeColumns``: only its part outside their span is back-substituted);
        a part on more nodes is back-substituted whole.
        """
        k = Grows.shape[0]
        X = np.zeros((self.nwatch, k))
        Xq = np.zeros(k)
        Gt = Grows.T.tocsr()
        for name, b in self.bodies.items():
            sl = slice(b.watch_offset, b.watch_offset + 2 * b.watch_nodes.size)
            sub = Gt[sl].tocsc()
            cols = np.flatnonzero(np.diff(sub.indptr))
            if cols.size == 0:
                continue
            if name in PATTERN_BODIES:
                split, Xs, Xsq, whole = self._node_columns(name, b).columns(
                    sub, lambda loads, name=name: self._node_response(name, loads), SOLVE_BATCH)
                X[sl, split] += Xs
                Xq[split] += Xsq
            else:
                whole = cols
            for c0 in range(0, whole.size, SOLVE_BATCH):
                cc = whole[c0:c0 + SOLVE_BATCH]
                Xw, Xwq = self._watch_response(name, self.watch_to_body(name, Gt[:, cc].tocsc()))
                X[sl, cc] += Xw
                Xq[cc] += Xwq
        return X, Xq

    def _node_columns(self, name: str, body: Body) -> ToothColumns:
        if name not in self._node_cache:
            ring = None
            if name in self.teeth:
                twist_response = self.unit_torque_u / self.f_scale if name == "fs" else None
                ring = RingColumns.for_body(body, self.teeth[name], self.half, twist_response)
            self._node_cache[name] = ring if ring is not None else NodeColumns(2 * body.watch_nodes.size)
        return self._node_cache[name]

    def plain_node_columns(self) -> None:
        """From now on, plain ``NodeColumns`` for every body (no turns by periods): the
        reference that ``RingColumns`` is checked against, and the fallback."""
        self.teeth = {}
        self._node_cache = {}

    def node_columns(self, name: str) -> ToothColumns:
        """The responses kept for loads on the nodes of body ``name``."""
        return self._node_columns(name, self.bodies[name])

    def adopt_node_columns(self, name: str, columns: ToothColumns) -> None:
        """Keep the node responses of body ``name`` in ``columns``, those of another structure
        with the same body (same factorisation and watch nodes): they are on the body's own
        watch dofs, whatever its place in either watch vector."""
        self._node_cache[name] = columns

    def _node_response(self, name: str, loads: list[tuple[np.ndarray, np.ndarray]]
                       ) -> tuple[np.ndarray, np.ndarray]:
        """``_watch_response`` to loads (the body's watch dofs, values) on body ``name``."""
        b = self.bodies[name]
        F = np.zeros((b.stiffness.shape[0], len(loads)))
        for j, (dofs, values) in enumerate(loads):
            F[b.dofs[dofs % 2, b.watch_nodes[dofs // 2]], j] = values
        return self._watch_response(name, F)

    def _watch_response(self, name: str, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """K^-1 F of body ``name`` (one back-substitution): its twist and its restriction to the
        body's own watch dofs (the only ones it moves)."""
        b = self.bodies[name]
        U = b.solve(F)
        wn = b.watch_nodes
        Uw = np.zeros((2 * wn.size, F.shape[1]))
        Uw[b.watch_index[0, wn] - b.watch_offset] = U[b.dofs[0, wn]]
        Uw[b.watch_index[1, wn] - b.watch_offset] = U[b.dofs[1, wn]]
        twist = self.twist_measure @ U if name == "fs" else np.zeros(F.shape[1])
        return Uw, twist

    def rigid_modes(self, modes: list[ModeName]) -> RigidModes:
        """Watch restriction, twist and torque-load component of the free modes ``modes``."""
        R = np.zeros((self.nwatch, len(modes)))
        Rq = np.zeros(len(modes))
        Rf = np.zeros(len(modes))
        for j, (bn, mn) in enumerate(modes):
            v = self.bodies[bn].modes[mn]
            R[:, j] = self.watch_vector(bn, v)
            if bn == "fs":
                Rq[j] = self.twist_measure @ v
                Rf[j] = self.f_scale * (self.twist_measure @ v)     # R^T f per unit torque
        return RigidModes(R, Rq, Rf)

    def full_displacements(self, forces: np.ndarray, torque: float, modes: list[ModeName],
                           amplitudes: np.ndarray) -> dict[str, np.ndarray]:
        """Displacement (2, nnodes) of every body, u = K^-1 (f + forces) + R alpha.

        Parameters
        ----------
        forces : numpy.ndarray
            Contact forces on the watch vector (G^T p, plus the friction forces).
        torque : float
            Torque on the FS rim (N mm).
        modes : list of (body, mode)
            The free rigid modes.
        amplitudes : numpy.ndarray
            Their amplitudes alpha.

        Returns
        -------
        dict[str, numpy.ndarray]
            Body name -> (2, nnodes) displacements (mm); one back-substitution per body.
        """
        force_watch = sp.csc_matrix(forces[:, None])
        out = {}
        for name, b in self.bodies.items():
            F = self.watch_to_body(name, force_watch)
            if name == "fs":
                F[:, 0] += torque * self.f_scale * self.twist_measure
            u = b.solve(F)[:, 0]
            for j, (bn, mn) in enumerate(modes):
                if bn == name:
                    u = u + amplitudes[j] * b.modes[mn]
            out[name] = np.vstack([u[b.dofs[0]], u[b.dofs[1]]])
        return out
