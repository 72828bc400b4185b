"""The compliant flank layer: each tooth pair's compliance from its share of the overlap integral.

A layer of compliance c per unit area (``ModelChanges.flank_layer_m``) between the flanks
presses with overlap / c; a tooth pair (a slave node) carries its node's share of that
pressure integrated along the slave outline, so its compliance is c / (b L) with b the face
width and L that share.  L depends on the gaps (where a contact ends inside an edge), so the
solver iterates it (``LayerIteration``), as it does the balls' Hertz secants.  Hand-written: no
library integrates a penalty layer over a node-to-segment contact of this kind.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from hdwf.fe.contact_geometry import match_to_outline

if TYPE_CHECKING:
    from hdwf.fe.bodies import Body


@dataclass(frozen=True)
class LayerEdges:
    """The slave boundary edges at the tooth pairs, for a flank layer whose pressure is the
    overlap over its compliance, integrated along the slave outline.

    A pair's force is its node's share of that integral: on an edge whose other end also
    overlaps, half the edge (the trapezoid rule, exact for a linear overlap); on an edge whose
    other end is clear, the overlap triangle up to the crossing, where the linear gap between
    the two ends changes sign.  So a node at the edge of a contact gets the force of the overlap
    that is there, not of half of each of its edges: a tip corner pressed into a flank carries
    the same force on any mesh (lumping it over half its edges made that force scale with the
    element size).
    """
    a: np.ndarray                 # (k,) row of one end of the edge, or -1
    b: np.ndarray                 # (k,) row of the other end, or -1
    half_length: np.ndarray       # (k,) half the edge's length (mm)
    gap_a: np.ndarray             # (k,) gap (mm) of end a where it is no row (at the rows' linearisation)
    gap_b: np.ndarray
    per_length: np.ndarray        # (n,) compliance times length (mm^2/N) of every row: s = per_length / L

    def compliance(self, gap: np.ndarray) -> np.ndarray:
        """The compliance (mm/N) of every row at the geometric gaps ``gap`` (mm, negative:
        overlap) of the rows: per_length over the row's share L of the overlap integral."""
        ga = np.where(self.a >= 0, gap[np.maximum(self.a, 0)], self.gap_a)
        gb = np.where(self.b >= 0, gap[np.maximum(self.b, 0)], self.gap_b)
        share, full = np.zeros(gap.size), np.zeros(gap.size)
        for row, g_own, g_other in ((self.a, ga, gb), (self.b, gb, ga)):
            on = row >= 0
            row, g_own, g_other, half = row[on], g_own[on], g_other[on], self.half_length[on]
            over, clear = np.maximum(-g_own, 0.0), np.maximum(g_other, 0.0)
            # the part of the half edge up to the crossing; a clear row keeps its whole half edge
            part = np.ones(row.size)
            cross = (over > 0) & (clear > 0)
            part[cross] = over[cross] / (over[cross] + clear[cross])
            np.add.at(share, row, half * part)
            np.add.at(full, row, half)
        return self.per_length / np.maximum(share, 1e-3 * full)


@dataclass(frozen=True)
class LayerPass:
    """One contact pass as the layer sees it: the slave nodes of ``slave_set`` on ``slave``
    are rows ``first_row``, ``first_row + 1``, ... of the stacked tooth rows, pressed against
    ``master_set`` of ``master``; ``per_length`` is the layer's compliance over the slave's face
    width (mm^2/N)."""
    slave: Body
    slave_nodes: np.ndarray
    slave_set: str
    master: Body
    master_set: str
    per_length: float
    first_row: int


def layer_edges(passes: Sequence[LayerPass], u_watch: np.ndarray) -> LayerEdges:
    """``LayerEdges`` of the passes: every slave edge with a row at one end at least; an end
    that is no row gets its gap to the master outline at ``u_watch``."""
    parts = []
    for p in passes:
        sb, sn = p.slave, p.slave_nodes
        E = sb.body_mesh.edge_sets[p.slave_set]
        row_of = -np.ones(sb.x.shape[1], dtype=np.int64)
        row_of[sn] = p.first_row + np.arange(sn.size)
        ra, rb = row_of[E[:, 0]], row_of[E[:, 1]]
        keep = (ra >= 0) | (rb >= 0)
        E, ra, rb = E[keep], ra[keep], rb[keep]
        others = np.unique(np.concatenate([E[ra < 0, 0], E[rb < 0, 1]]))
        gap_of = np.full(sb.x.shape[1], -np.inf)    # not watched: the end counts as overlapping
        others = others[sb.watch_index[0, others] >= 0]
        if others.size:
            gap_of[others] = match_to_outline(sb, others, p.master, p.master_set, u_watch).gap
        length = np.hypot(*(sb.x[:, E[:, 1]] - sb.x[:, E[:, 0]]))
        parts.append((ra, rb, 0.5 * length, gap_of[E[:, 0]], gap_of[E[:, 1]],
                      np.full(sn.size, p.per_length)))
    return LayerEdges(*(np.concatenate(x) for x in zip(*parts)))


@dataclass
class LayerIteration:
    """The flank layer's compliances iterated to their shares at the solved gaps (one level).

    ``step`` takes the pairs' solved forces and gaps and the compliances they were solved with,
    and returns the compliances for the next solve and how far the shares at the solved gaps
    move an approach s p (settled below the gap tolerance).  The update is a secant step on
    r = log s_target - log s per pair: where the force is held (at the edge of a contact,
    s_target ~ 1/s) the slope is -2 and a plain update swings between two values; where the
    overlap is held it is -1; the secant finds either root in one step.  The first step, and
    any whose slope is outside [-4, -0.25], goes half way in log s (the geometric mean).
    """
    layer: LayerEdges
    ti: np.ndarray                      # the tooth pairs' positions among the stacked pairs
    _last: tuple[np.ndarray, np.ndarray] | None = None    # (log s, r) of the last step

    def step(self, force: np.ndarray, gap: np.ndarray, s_rows: np.ndarray) -> tuple[np.ndarray, float]:
        ti = self.ti
        pt = np.maximum(force[ti], 0.0)
        s = s_rows[ti]
        s_target = self.layer.compliance(gap[ti] - s * pt)
        residual = float(np.max(np.abs(s_target - s) * pt, initial=0.0))
        x, r = np.log(s), np.log(s_target) - np.log(s)
        x_next = x + 0.5 * r
        if self._last is not None:
            dx, dr = x - self._last[0], r - self._last[1]
            moved = np.abs(dx) > 1e-12
            slope = np.where(moved, dr / np.where(moved, dx, 1.0), 0.0)
            secant = moved & (slope < -0.25) & (slope > -4.0)
            x_next[secant] = x[secant] - r[secant] / slope[secant]
        self._last = (x, r)
        s_next = s_rows.copy()
        s_next[ti] = np.exp(x_next)
        return s_next, residual
