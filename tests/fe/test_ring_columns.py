"""Columns of the toothed rings turned from one period's equal the direct back-substitution."""

import numpy as np
import pytest
import scipy.sparse as sp

from hdwf.fe.bodies import Body
from hdwf.fe.model import ZONE_DEG
from hdwf.fe.ring_columns import RingColumns, RingTurns

from tests.fe.test_node_columns import _direct, _structure

# the FS floats, pinned at one dof: its turned and direct columns agree to 1e-9..2e-8 of their
# size (measured), not to the CS's 1e-13
TOL = 1e-7


def _tooth_rows(structure, rows):
    """Contact-like rows: (body, watch nodes, weights, normal angle) each."""
    r, c, v = [], [], []
    for i, (name, nodes, weights, angle) in enumerate(rows):
        b = structure.bodies[name]
        n = np.array([np.cos(angle), np.sin(angle)])
        for node, w in zip(nodes, weights):
            for k in (0, 1):
                r.append(i)
                c.append(b.watch_offset + 2 * node + k)
                v.append(w * n[k])
    return sp.csr_matrix((v, (r, c)), shape=(len(rows), structure.nwatch))


def _near_major_axis(body):
    """The watch node at the smallest angle above the major axis (angle 0)."""
    x = body.x[:, body.watch_nodes]
    angle = np.arctan2(x[1], x[0])
    angle[angle <= 1e-6] = np.inf
    return int(np.argmin(angle))


def _same_node_turned(body, teeth, node, periods):
    """The watch node ``periods`` periods on from watch node ``node`` (same place in its tooth)."""
    x = body.x[:, body.watch_nodes[node]]
    a = 2 * np.pi * periods / teeth
    y = np.array([np.cos(a) * x[0] - np.sin(a) * x[1], np.sin(a) * x[0] + np.cos(a) * x[1]])
    d = np.hypot(*(body.x[:, body.watch_nodes] - y[:, None]))
    assert d.min() < 1e-9
    return int(np.argmin(d))


@pytest.mark.parametrize("symmetry", ["half", "full"])
def test_turned_columns_equal_direct_back_substitution(symmetry, monkeypatch):
    """K^-1 commutes with turning the ring by a period, so a row on the teeth of another period
    answers as its base-period row turned: the same columns and twists as one back-substitution
    per row (the FS floating, its rigid modes pinned; the CS clamped at its rim), with no new
    back-substitution for the turned rows."""
    structure = _structure(symmetry, rings=True)
    fs, cs = structure.bodies["fs"], structure.bodies["cs"]
    assert type(structure.node_columns("fs")) is RingColumns
    assert type(structure.node_columns("cs")) is RingColumns
    zf, zc = structure.teeth["fs"], structure.teeth["cs"]
    f0, c0 = _near_major_axis(fs), _near_major_axis(cs)
    first = [("fs", [f0], [1.0], 0.4), ("cs", [c0, c0 + 1], [-0.7, -0.3], 0.4 + np.pi)]
    solved = []
    original = Body.solve
    monkeypatch.setattr(Body, "solve", lambda self, F: solved.append((self.name, F.shape[1]))
                        or original(self, F))
    G1 = _tooth_rows(structure, first)
    X1, Xq1 = structure.compliance_columns(G1)
    n_first = len(solved)
    # the same rows 5 and 12 periods on (within the watched zone), their normals turned with them
    turned = []
    for p in (5, 12):
        a = 2 * np.pi * p
        turned += [("fs", [_same_node_turned(fs, zf, f0, p)], [1.0], 0.4 + a / zf),
                   ("cs", [_same_node_turned(cs, zc, c0, p), _same_node_turned(cs, zc, c0 + 1, p)],
                    [-0.7, -0.3], 0.4 + np.pi + a / zc)]
    G2 = _tooth_rows(structure, turned)
    X2, Xq2 = structure.compliance_columns(G2)
    monkeypatch.undo()
    assert len(solved) == n_first, "turned rows need no back-substitution"
    for G, X, Xq in ((G1, X1, Xq1), (G2, X2, Xq2)):
        Xd, Xqd = _direct(structure, G)
        assert np.abs(X - Xd).max() <= TOL * np.abs(Xd).max()
        assert np.abs(Xq - Xqd).max() <= TOL * np.abs(Xqd).max()


@pytest.mark.parametrize("zone_deg, periods", [(ZONE_DEG, (3, 9)), (90.0, (5, 40, 70))])
def test_responses_are_kept_where_a_turn_reads_them(zone_deg, periods):
    """With every tooth watched (a preload's 90 degree zones) a turn reads a watch node's response
    from another watch node, so the base responses are kept at the watch nodes (and the FS pin's
    turned places) only, a fraction of the body's nodes; with the teeth watched in zones a turn
    reads from outside them, so every node is kept.  Either way a row on any watched tooth answers
    as its direct back-substitution."""
    structure = _structure("half", rings=True, zone_deg=zone_deg)
    rows = []
    for name, angle in (("fs", 0.4), ("cs", 0.4 + np.pi)):
        b, ring = structure.bodies[name], structure.node_columns(name)
        assert type(ring) is RingColumns
        kept = np.flatnonzero(ring._rows[0] >= 0)
        n_nodes = b.dofs.shape[1]
        if zone_deg == ZONE_DEG:
            assert kept.size == n_nodes
        else:
            assert np.isin(b.watch_nodes, kept).all()
            assert kept.size <= b.watch_nodes.size + ring.turns.periods * ring._pin_nodes.size
            assert kept.size < 0.3 * n_nodes
        node0 = _near_major_axis(b)
        rows.append((name, [node0], [1.0], angle))
        for p in periods:
            a = 2 * np.pi * p / structure.teeth[name]
            rows.append((name, [_same_node_turned(b, structure.teeth[name], node0, p)], [1.0], angle + a))
    G = _tooth_rows(structure, rows)
    X, Xq = structure.compliance_columns(G)
    Xd, Xqd = _direct(structure, G)
    assert np.abs(X - Xd).max() <= TOL * np.abs(Xd).max()
    assert np.abs(Xq - Xqd).max() <= TOL * np.abs(Xqd).max()


def test_turns_make_a_group_that_closes_after_a_full_turn():
    """S_p = S_1^p, and turning a field by all the periods of the model (half: pi, which a
    point-symmetric field does not see) gives it back unchanged."""
    structure = _structure("half", rings=True)
    for name in ("fs", "cs"):
        b = structure.bodies[name]
        turns = RingTurns(b.x, structure.teeth[name], half=True)
        ring = structure.node_columns(name)
        v = b.tie @ np.random.default_rng(1).standard_normal(b.tie.shape[1])
        field = np.vstack([v[b.dofs[0]], v[b.dofs[1]]])
        all_nodes = np.arange(b.x.shape[1])
        full = ring._turn(v, turns.periods, all_nodes)
        assert np.abs(full - field).max() <= 1e-12 * np.abs(field).max()
        two = ring._turn(v, 2, all_nodes)
        one = ring._turn(v, 1, all_nodes)
        w = np.zeros_like(v)
        w[b.dofs[0]], w[b.dofs[1]] = one
        assert np.abs(ring._turn(w, 1, all_nodes) - two).max() <= 1e-12 * np.abs(field).max()


def test_a_body_that_is_not_such_a_ring_keeps_plain_columns():
    """The wrong tooth count (turned nodes land between nodes) or a ring without periods (the
    bearing's outer ring) is refused, so the plain node columns stay in use."""
    structure = _structure("half", rings=True)
    fs = structure.bodies["fs"]
    with pytest.raises(ValueError, match="not periodic with 241 teeth"):
        RingTurns(fs.x, 241, half=True)
    assert RingColumns.for_body(fs, 241, True, None) is None
    assert RingColumns.for_body(structure.bodies["or"], 240, True, None) is None
