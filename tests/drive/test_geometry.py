"""Geometry of the two drives: cam of Eq. 3, involute flanks with normal offsets, mesh."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from hdwf.drive.cam import cam_radius
from hdwf.drive.geometry import (ARCMIN, cs_half_space_angle, drive_geometry, fs_half_angle,
                                 geometric_backlash_arcmin, nominal_geometry)


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_cam_perimeter_equals_pi_d(unit):
    """The inner-ring bore (pi d) is inextensible and wraps the cam: the perimeter of
    Eq. 3, integrated independently of the polyline used to size it, must equal pi d to
    well below the 0.1 um the contact is resolved to (n = 1: R' = -2 B sin 2 phi)."""
    g = nominal_geometry(unit)
    assert g.cam_n == 1.0
    A, B = g.cam_A, g.cam_B
    per = 4 * quad(lambda p: math.hypot(A + B * math.cos(2 * p), 2 * B * math.sin(2 * p)),
                   0, math.pi / 2, epsabs=1e-13)[0]
    assert abs(per - math.pi * g.d_nom) < 1e-6


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_cam_gives_w0_equal_module(unit):
    """Nominal bearing, rigid: FS radial deflection at the major axis = cam excess over
    the bore radius minus the ball gap G_r/2 = m (2-tooth difference); and A agrees with
    the background's A ~ r - B^2/r up to its O(B^4/r^3) error (< 1e-5 mm here)."""
    g = nominal_geometry(unit)
    w = float(cam_radius(0.0, g.cam_A, g.cam_B, g.cam_n)) - g.d_nom / 2 - g.Gr_nom / 2
    assert abs(w - g.module) < 1e-9
    r = g.d_nom / 2
    assert abs(g.cam_A - (r - g.cam_B ** 2 / r)) < 1e-5
    # minor axis radius is A - B, mirrored curve is continuous at pi/2
    assert abs(float(cam_radius(math.pi / 2, g.cam_A, g.cam_B, g.cam_n))
               - (g.cam_A - g.cam_B)) < 1e-12


def test_paper_geometry_values():
    """Table 1-3 data and the derived module / test torque land in the geometry."""
    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0)
    assert (g.z_fs, g.z_cs) == (240, 242)
    assert g.torque == pytest.approx(960.0)          # 4 % of 24 N m, N mm
    assert g.r_fs_tip - g.r_fs_root == pytest.approx(0.337)   # paper's tooth height
    assert g.w0 == pytest.approx(0.18)
    h = drive_geometry("hd120", 90.0, 120.0, 0.03, 0.025, 0.025)
    assert h.torque == pytest.approx(21160.0)
    assert h.r_cs_root - h.r_cs_tip == pytest.approx(1.0)
    # 1 arcmin on the pitch circle ~ 6.3 um (HD 42), ~17.9 um (HD 120): background table
    assert 1 / g.arcmin_per_um == pytest.approx(6.28, abs=0.05)
    assert 1 / h.arcmin_per_um == pytest.approx(17.9, abs=0.1)


def _flank_xy(g, r, which):
    if which == "fs":
        a = -fs_half_angle(g, r)
    else:
        a = -cs_half_space_angle(g, r)
    return np.column_stack([r * np.cos(a), r * np.sin(a)])


@pytest.mark.parametrize("which", ["fs", "cs"])
def test_offset_is_normal_to_flank(which):
    """r_FS / r_CS offset every flank point by exactly that distance along the normal
    (an involute offset is the same involute turned by offset/r_b): distance from dense
    offset-flank points to the dense nominal flank equals 10 um within 1 nm."""
    off = 0.010
    kw = dict(rFS_mm=off, rCS_mm=0.0) if which == "fs" else dict(rFS_mm=0.0, rCS_mm=off)
    g0 = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0)
    g1 = drive_geometry("hd42", 31.0, 42.0, 0.015, **kw)
    lo, hi = (g0.r_fs_root, g0.r_fs_tip) if which == "fs" else (g0.r_cs_tip, g0.r_cs_root)
    nom = _flank_xy(g0, np.linspace(lo - 0.05, hi + 0.05, 200001), which)
    test = _flank_xy(g1, np.linspace(lo + 0.05, hi - 0.05, 7), which)
    from scipy.spatial import cKDTree
    dist, _ = cKDTree(nom).query(test)
    assert np.allclose(dist, off, atol=1e-6)


def test_zero_offset_is_zero_backlash_and_backlash_formula():
    """Zero offsets: FS tooth thickness = CS space width = pi m / 2 on the pitch circles
    (zero backlash at the major axis); the rigid-body backlash is 2 (r_FS + r_CS)/r_b,CS:
    10 + 10 um on HD 42 -> 2 * 0.02 / 20.4665 rad = 6.719 arcmin."""
    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0)
    s = 2 * fs_half_angle(g, g.r_fs_pitch) * g.r_fs_pitch
    e = 2 * cs_half_space_angle(g, g.r_cs_pitch) * g.r_cs_pitch
    assert s == pytest.approx(math.pi * g.module / 2, rel=1e-12)
    assert e == pytest.approx(math.pi * g.module / 2, rel=1e-12)
    assert geometric_backlash_arcmin(g) == 0.0
    g2 = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.010, 0.010)
    expect = 2 * 0.020 / (g2.r_cs_pitch * math.cos(math.radians(20))) / ARCMIN
    assert geometric_backlash_arcmin(g2) == pytest.approx(expect, rel=1e-12)
    assert expect == pytest.approx(6.719, abs=0.002)


@pytest.mark.slow
def test_mesh_groups_and_density(tmp_path):
    """Coarse mesh: all 240 / 242 teeth present, named groups, .msh written; each flank
    carries elements_over_height segments."""
    from hdwf.drive.mesh import build_mesh
    g = nominal_geometry("hd42")
    path = tmp_path / "hd42.msh"
    m = build_mesh(g, elements_over_height=4, elements_over_thickness=3, refinement=1.0,
                   path=str(path))
    assert path.exists() and path.stat().st_size > 0
    assert set(m.bodies) == {"fs", "cs", "ir", "or"}
    fs, cs = m.bodies["fs"], m.bodies["cs"]
    for key in ("fs_teeth", "fs_bore"):
        assert key in fs.node_sets
    for key in ("cs_teeth", "cs_outer"):
        assert key in cs.node_sets
    # count teeth: tip nodes of the FS sit at r_tip, one cluster per tooth
    p = fs.mesh.p[:, fs.node_sets["fs_teeth"]]
    r = np.hypot(p[0], p[1])
    tips = np.arctan2(p[1], p[0])[np.abs(r - g.r_fs_tip) < 1e-9]
    clusters = np.unique(np.round(tips / (2 * math.pi / 240)).astype(int) % 240)
    assert clusters.size == 240
    pc = cs.mesh.p[:, cs.node_sets["cs_teeth"]]
    rc = np.hypot(pc[0], pc[1])
    tipc = np.arctan2(pc[1], pc[0])[np.abs(rc - g.r_cs_tip) < 1e-9]
    cl = np.unique(np.floor(np.mod(tipc, 2 * math.pi) / (2 * math.pi / 242)).astype(int))
    assert cl.size == 242
    # flank segments: boundary edges per FS tooth ~ 2 flanks * 4 + tip + root segments
    assert fs.edge_sets["fs_teeth"].shape[0] >= 240 * (2 * 4 + 2)


def test_every_constant_has_a_source():
    """The one table of values stays complete: each field of UnitData has a unit and a source."""
    import dataclasses

    from hdwf.drive.geometry import _SOURCES, UnitData, assumptions_table

    assert {f.name for f in dataclasses.fields(UnitData)} == set(_SOURCES)
    assert all(row["source"] for row in assumptions_table())


def test_radial_offsets_are_rack_shifts():
    """offset_direction "radial": r_FS, r_CS shift the cutting rack radially, which moves each
    involute flank normally by r sin(alpha); the outline is that of normal offsets r sin(alpha),
    and the rigid backlash 2 (r_FS + r_CS) sin(alpha) / r_b."""
    radial = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.012, 0.008, offset_direction="radial")
    k = math.sin(radial.alpha)
    normal = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.012 * k, 0.008 * k)
    r = np.linspace(radial.r_fs_root, radial.r_fs_tip, 5)
    assert np.allclose(fs_half_angle(radial, r), fs_half_angle(normal, r), rtol=0, atol=1e-15)
    rc = np.linspace(radial.r_cs_tip, radial.r_cs_root, 5)
    assert np.allclose(cs_half_space_angle(radial, rc), cs_half_space_angle(normal, rc), rtol=0, atol=1e-15)
    expect = 2 * 0.020 * k / radial.r_cs_base / ARCMIN
    assert geometric_backlash_arcmin(radial) == pytest.approx(expect, rel=1e-12)
    with pytest.raises(ValueError, match="offset_direction"):
        drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0, offset_direction="tangential")
