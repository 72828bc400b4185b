"""Rounded tip corners (``drive_geometry(tip_round_m=...)``, ``hdwf.drive.sector_mesh``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hdwf.drive.geometry import drive_geometry
from hdwf.drive.mesh import build_mesh
from hdwf.drive.sector_mesh import round_corner_geometry

RHO_M = 0.1


def _distance_to_line(point, through, direction) -> float:
    d = np.asarray(direction, float) / np.hypot(*direction)
    v = np.asarray(point, float) - np.asarray(through, float)
    return abs(v[0] * d[1] - v[1] * d[0])


@pytest.mark.parametrize("beta_deg, outward", [(90.0, -1.0), (115.0, -1.0), (150.0, -1.0), (115.0, 1.0)])
def test_round_touches_the_flank_and_the_tip_circle(beta_deg, outward):
    """A round of radius rho in a tip corner of interior angle beta (the flank running into
    the tooth, inward for an FS tooth, outward for a CS one): its centre lies rho from the
    flank and rho inside (FS) or outside (CS) the tip circle, both tangent points lie rho
    from it, one on the flank, one on the tip circle, and the flank's lies t = rho / tan(beta/2)
    from the corner as at a straight land (to the tip circle's curvature: relative rho / R)."""
    rho, R = 0.05, 20.0
    corner = np.array([R, 0.0])
    land = np.array([0.0, 1.0])                  # land_sign +1 at (R, 0): toward larger angle
    beta = math.radians(beta_deg)
    flank = np.array([outward * math.sin(beta), math.cos(beta)])     # at beta from the land
    on_flank, on_land, centre, t = round_corner_geometry(corner, corner + 3.0 * flank, +1.0, rho)
    assert np.hypot(*centre) == pytest.approx(R + outward * rho, rel=1e-14)
    assert _distance_to_line(centre, corner, flank) == pytest.approx(rho, rel=1e-12)
    assert np.hypot(*(centre - on_flank)) == pytest.approx(rho, rel=1e-12)
    assert np.hypot(*(centre - on_land)) == pytest.approx(rho, rel=1e-12)
    assert np.hypot(*on_land) == pytest.approx(R, rel=1e-15)
    assert _distance_to_line(on_flank, corner, flank) < 1e-14
    assert t == pytest.approx(rho / math.tan(beta / 2.0), rel=2.0 * rho / R)
    assert (on_land - corner) @ land > 0.0 and (on_flank - corner) @ flank > 0.0


def _circle_through(a, b, c):
    """Centre and radius of the circle through three points."""
    (ax, ay), (bx, by), (cx, cy) = a, b, c
    d = 2.0 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    ux = ((ax * ax + ay * ay) * (by - cy) + (bx * bx + by * by) * (cy - ay) + (cx * cx + cy * cy) * (ay - by)) / d
    uy = ((ax * ax + ay * ay) * (cx - bx) + (bx * bx + by * by) * (ax - cx) + (cx * cx + cy * cy) * (bx - ax)) / d
    return np.array([ux, uy]), math.hypot(ax - ux, ay - uy)


def _round_nodes(bm, group, r_tip, rho, inward, theta_lo, theta_hi):
    """The outline nodes of one tip round: the land node nearest the corner, then those
    below the tip circle by less than 0.9 rho (the round reaches about 0.6 rho deep), by angle."""
    p = bm.mesh.p
    n = np.unique(bm.edge_sets[group])
    r, th = np.hypot(*p[:, n]), np.arctan2(p[1, n], p[0, n])
    in_tooth = (th > theta_lo) & (th < theta_hi)
    depth = (r - r_tip) * inward
    on_land = n[in_tooth & (np.abs(depth) < 1e-12)]
    on_round = n[in_tooth & (depth > 1e-7) & (depth < 0.9 * rho)]
    return on_land, on_round


@pytest.fixture(scope="module")
def preloaded():
    """An HD 42 design with the studies' preload profile (0.3 m, tip relief 1.1)."""
    return dict(unit="hd42", d_mm=31.0, D_mm=42.0, Gr_mm=0.015, rFS_mm=0.005, rCS_mm=0.005,
                interference_m=0.3, tip_relief=1.1)


@pytest.mark.parametrize("refinement, segments", [(1.0, 2), (1.5, 3)])
def test_meshed_rounds_have_the_radius_and_touch_the_tip_circle(preloaded, refinement, segments):
    """Each tip corner of FS and CS is an arc of ``segments`` segments (a fifth of a flank's):
    the circle through its three outermost nodes has radius rho = 0.1 m and is tangent to the
    tip circle (its centre rho inside the FS tip circle, rho outside the CS one)."""
    g = drive_geometry(**preloaded, tip_round_m=RHO_M)
    rho = RHO_M * g.module
    m = build_mesh(g, 10, 6, refinement, symmetry="half", bodies=("fs", "cs"))
    a_fs, a_cs = 2 * math.pi / g.z_fs, 2 * math.pi / g.z_cs
    # FS tooth 0 is centred on angle 0 (tip outward): its corner on the side of positive angle
    land, rnd = _round_nodes(m.bodies["fs"], "fs_teeth", g.r_fs_tip, rho, -1.0, 0.0, a_fs / 2)
    assert len(rnd) == segments
    p = m.bodies["fs"].mesh.p
    t2 = land[np.argmax(np.arctan2(p[1, land], p[0, land]))]
    chain = [t2] + list(rnd[np.argsort(np.hypot(*p[:, rnd]))[::-1]])
    centre, radius = _circle_through(*(p[:, k] for k in chain[:3]))
    assert radius == pytest.approx(rho, rel=1e-6)
    assert np.hypot(*centre) == pytest.approx(g.r_fs_tip - rho, abs=1e-6 * rho)
    # CS: space 0 centred on angle 0, the tooth after it (tip inward) has its corner beyond it
    land, rnd = _round_nodes(m.bodies["cs"], "cs_teeth", g.r_cs_tip, rho, +1.0, 0.0, a_cs / 2)
    assert len(rnd) == segments
    p = m.bodies["cs"].mesh.p
    t2 = land[np.argmin(np.arctan2(p[1, land], p[0, land]))]
    chain = [t2] + list(rnd[np.argsort(np.hypot(*p[:, rnd]))])
    centre, radius = _circle_through(*(p[:, k] for k in chain[:3]))
    assert radius == pytest.approx(rho, rel=1e-6)
    assert np.hypot(*centre) == pytest.approx(g.r_cs_tip + rho, abs=1e-6 * rho)


def test_sharp_tips_have_no_round(preloaded):
    """``tip_round_m`` 0 (the default) keeps the corner: no outline node between the tip
    circle and the first flank node below it within 0.9 rho."""
    g = drive_geometry(**preloaded)
    m = build_mesh(g, 10, 6, 1.0, symmetry="half", bodies=("fs",))
    _, rnd = _round_nodes(m.bodies["fs"], "fs_teeth", g.r_fs_tip, RHO_M * g.module, -1.0, 0.0,
                          math.pi / g.z_fs)
    assert len(rnd) == 0


@pytest.mark.parametrize("value", [-0.1, 0.3, float("nan")])
def test_tip_round_out_of_range_is_refused(value):
    with pytest.raises(ValueError, match=r"tip_round_m must be in \[0, 0.25\].*got"):
        drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0, tip_round_m=value)
