"""Contact geometry of the tooth rows: the gap of a point beyond the end of a segment."""

import math

import numpy as np
import pytest

from hdwf.fe.contact_geometry import closest_segments


def test_closest_segment_gap_is_corner_distance_beyond_a_segment():
    """A tip land from (0, 0) to (1, 0), material above it (outward normal -y), and a flank
    rising from its right corner to (1.6, 2). A point in the fan outside that corner, beyond
    the end of both segments, is its distance from the corner away (0.36), not the land-normal
    offset 0.2: that offset is the gap to the land's straight extension, which let FS flank
    nodes beside a CS tooth "touch" a tip land that is not there (hd42-lhs-22, 2.5 % between
    meshes). A point under the land keeps its normal gap; one above it penetrates."""
    xa = np.array([[0.0, 1.0], [0.0, 0.0]])          # land (0,0)->(1,0), flank (1,0)->(1.6,2)
    xb = np.array([[1.0, 1.6], [0.0, 2.0]])
    d = xb - xa
    nrm = np.vstack([d[1], -d[0]]) / np.linalg.norm(d, axis=0)   # right-hand normals
    nrm[:, 0] = [0.0, -1.0]                          # land faces down (out of the material)
    pts = np.array([[1.3, -0.2], [0.5, -0.2], [0.5, 0.05]]).T
    gap, seg, t = closest_segments(pts, xa, xb, nrm)
    assert gap[0] == pytest.approx(math.hypot(0.3, 0.2))
    assert (seg[0], t[0]) in [(0, 1.0), (1, 0.0)]    # the corner, from either segment
    assert gap[1] == pytest.approx(0.2) and seg[1] == 0
    assert gap[2] == pytest.approx(-0.05) and seg[2] == 0


def test_closest_segment_gap_is_negative_when_sunk_in_at_a_concave_vertex():
    """Two segments meeting at a concave vertex (0, 0) of the material below them (an
    internal gear's flank is such a polyline), outward normals pointing up-and-in.  A point
    that has sunk in just under the vertex projects beyond the ends of both segments; it lies
    behind both, so it penetrates by its distance to the vertex (a convex corner's fan always
    lies in front of one of its segments).  Before this rule it was reported as a gap of that
    distance: with a preload the ramp saw 65 um jumps."""
    xa = np.array([[-1.0, 0.0], [0.5, 0.0]])          # (-1, 0.5) -> (0, 0) -> (1, 0.5)
    xb = np.array([[0.0, 1.0], [0.0, 0.5]])
    d = xb - xa
    nrm = np.vstack([-d[1], d[0]]) / np.linalg.norm(d, axis=0)   # left-hand normals: up
    assert nrm[1].min() > 0
    pts = np.array([[0.0, -0.03], [0.0, 0.3], [-0.5, 0.2]]).T
    gap, seg, _ = closest_segments(pts, xa, xb, nrm)
    assert gap[0] == pytest.approx(-0.03)                          # sunk in at the vertex
    # above it: outside, measured along either segment's normal (it projects inside both), not
    # to the vertex (0.3): the concave-vertex rule is for points behind both segments only
    assert gap[1] == pytest.approx(0.3 * 2 / math.sqrt(5))
    assert gap[2] == pytest.approx((0.2 - 0.25) * 2 / math.sqrt(5)) and seg[2] == 0
