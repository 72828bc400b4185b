"""Tip relief (``DriveGeometry.tip_relief``): derived from the FS tooth's path, it clears the
exit zone where the plain involute tips cross each other.

The analytic tests need no mesh; the outline test meshes one coarse half model; the
exit-zone tests mount the wave generator only (no torque sequence), seconds each.
"""

import math

import numpy as np
import pytest

from hdwf.drive.geometry import cs_half_space_angle, drive_geometry, fs_half_angle
from hdwf.drive.mesh import build_mesh
from hdwf.drive.relief import PRELOAD_TIP_RELIEF, relief_start_depth, tip_relief
from hdwf.fe import ISO76_BALL_PRESSURE_MPA, LostMotionModel, ball_max_pressure, solve_lost_motion
from hdwf.fe.cycle import mount_wave_generator

COARSE = {"elements_over_height": 5, "elements_over_thickness": 3, "symmetry": "half"}
NOMINAL = {"hd42": (31.0, 42.0, 0.015, 0.0, 0.0), "hd120": (90.0, 120.0, 0.030, 0.0, 0.0)}
CHOSEN = PRELOAD_TIP_RELIEF     # the multiple of the derived relief a preload is solved with


def _path(g, phi):
    """The FS tooth at phi on the rack path: withdrawal Delta, advance s, overlap e."""
    m, a = g.module, g.alpha
    delta = m * (1 - np.cos(2 * phi))
    s = 0.5 * m * (2 * phi - g.tilt_factor * np.sin(2 * phi))
    return delta, s, s - delta * math.tan(a)


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_relief_covers_the_crossing_and_no_more(unit):
    """Wherever the path makes the tips cross (e > 0 over the band of depth D between the
    tips), the two reliefs facing each other add up to at least e at every height of the
    band, and to exactly e where a tip just meets the other tooth (d_FS = D, d_CS = 0):
    the least relief split evenly.  Below the start depth both flanks are untouched."""
    g = drive_geometry(unit, *NOMINAL[unit], tip_relief=1.0)
    ha = g.addendum
    c = lambda d: tip_relief(d, g.module, ha, g.alpha, g.tilt_factor)
    phi = np.radians(np.linspace(1.0, 89.0, 400))
    delta, _, e = _path(g, phi)
    band = 2 * ha - delta
    d0 = relief_start_depth(g.module, ha, g.alpha, g.tilt_factor)
    crossing = (e > 0) & (band > 0) & (band <= d0)     # the exit branch (phi > 51 deg)
    assert crossing.sum() > 10            # the plain tips do cross (51-69 deg)
    for D, ek in zip(band[crossing], e[crossing]):
        d_fs = np.linspace(0.0, D, 41)
        assert np.all(c(d_fs) + c(D - d_fs) >= ek * (1 - 1e-9))
        assert 2 * c(D) == pytest.approx(ek, rel=1e-9)
    assert 0 < d0 < ha
    assert c(d0 * 1.0001) == 0.0 and c(np.linspace(d0, 2 * ha, 5)).max() < 1e-12
    assert c(0.0) > c(0.5 * d0) > 0


def test_relieved_flanks_are_the_plain_involutes_less_the_relief():
    """FS teeth thinner and CS spaces wider by relief(depth) / r; nothing changes below the
    start depth; tip_relief = 0 is the plain profile (the default, same geometry)."""
    g0 = drive_geometry("hd42", *NOMINAL["hd42"])
    g1 = drive_geometry("hd42", *NOMINAL["hd42"], tip_relief=1.0)
    assert drive_geometry("hd42", *NOMINAL["hd42"], tip_relief=0.0) == g0
    r = np.linspace(g1.r_fs_root, g1.r_fs_tip, 50)
    dfs = fs_half_angle(g0, r) - fs_half_angle(g1, r)
    assert np.allclose(dfs * r, g1.relief(g1.r_fs_tip - r), rtol=0, atol=1e-12)
    rc = np.linspace(g1.r_cs_tip, g1.r_cs_root, 50)
    dcs = cs_half_space_angle(g1, rc) - cs_half_space_angle(g0, rc)
    assert np.allclose(dcs * rc, g1.relief(rc - g1.r_cs_tip), rtol=0, atol=1e-12)
    with pytest.raises(ValueError):
        drive_geometry("hd42", *NOMINAL["hd42"], tip_relief=-1.0)


def test_meshed_outline_follows_the_relief():
    """The meshed FS flank nodes lie on the relieved involute (spline through 20 points, 8
    of them over the relieved depth): the tip corner is narrower by relief(0) / r_tip."""
    g = drive_geometry("hd42", *NOMINAL["hd42"], tip_relief=1.0)
    mesh = build_mesh(g, elements_over_height=10, elements_over_thickness=3, symmetry="half")
    fs = mesh.bodies["fs"]
    x = fs.mesh.p[:, fs.node_sets["fs_teeth"]]
    r, th = np.hypot(*x), np.arctan2(x[1], x[0])
    pitch = 2 * math.pi / g.z_fs
    local = np.abs(th - pitch * np.round(th / pitch))
    flank = (r > g.r_fs_root + 1e-6) & (r < g.r_fs_tip - 1e-6)
    err = (local[flank] - fs_half_angle(g, r[flank])) * r[flank]
    assert np.abs(err).max() < 0.02 * g.relief(0.0)
    corner = np.abs(r - g.r_fs_tip) < 1e-9
    plain = drive_geometry("hd42", *NOMINAL["hd42"])
    narrower = (fs_half_angle(plain, g.r_fs_tip) - local[corner].max()) * g.r_fs_tip
    assert narrower == pytest.approx(g.relief(0.0), rel=1e-3)


def _exit_overlap_um(unit, relief):
    g = drive_geometry(unit, *NOMINAL[unit], tip_relief=relief)
    model = LostMotionModel(g, build_mesh(g, **COARSE))
    return mount_wave_generator(model).outside_overlap_um


@pytest.mark.slow
@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_exit_zone_is_clear_at_the_nominal_design(unit):
    """Mounted nominal design (zero offsets, zero interference, w0 = m), coarse mesh: the
    plain involute tips cross outside the watched zones by tens of micrometres; the
    derived relief takes out most of it (the elastic FS withdraws 2-4 % less than
    w0 (1 - cos 2 phi) near 66-69 deg), and the chosen multiple 1.1 clears it."""
    assert _exit_overlap_um(unit, 0.0) > 20.0
    assert _exit_overlap_um(unit, 1.0) < 0.35 * _exit_overlap_um(unit, 0.0)
    assert _exit_overlap_um(unit, CHOSEN) <= 0.0


@pytest.mark.slow
def test_loaded_arc_shows_where_the_torque_is_carried():
    """``loaded_arc_deg``: the loaded tooth at +T farthest from a major axis.  With the offsets
    past the preload allowance only the working mesh next to the major axis carries the torque
    (a few teeth within 20°); HD 42's loosest bearing of Table 3 (d, D, G_r at their clearance
    bounds) with zero offsets and a heavy allowance pushes the FS so far back that teeth all
    round, out to the minor axis, are loaded: the exit-zone tip crossings the diagnostic is
    there to show (docs/fe-alternatives.md, "Where the torque is carried").  The tight design's
    preload loads its most loaded wave-generator ball beyond ISO 76's static rating (4200 MPa);
    the open one's balls carry only the FS ring's bending, tens of newtons."""
    g_open = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.02, 0.02, interference_m=0.17,
                            tip_relief=PRELOAD_TIP_RELIEF)
    r_open = solve_lost_motion(g_open, build_mesh(g_open, **COARSE), steps_per_ramp=1)
    g_tight = drive_geometry("hd42", 31.016, 41.984, 0.020, 0.0, 0.0, interference_m=0.17,
                             tip_relief=PRELOAD_TIP_RELIEF)
    r_tight = solve_lost_motion(g_tight, build_mesh(g_tight, **COARSE), steps_per_ramp=1)
    assert r_open.status == r_tight.status == "ok"
    assert r_open.loaded_arc_deg < 20.0 and r_open.teeth_in_contact <= 12
    assert r_tight.loaded_arc_deg > 60.0 and r_tight.teeth_in_contact > 100
    assert r_open.max_ball_load_N < 50.0 and r_open.max_ball_pressure_MPa < ISO76_BALL_PRESSURE_MPA
    assert r_tight.max_ball_pressure_MPa > ISO76_BALL_PRESSURE_MPA
    assert r_tight.max_ball_pressure_MPa == pytest.approx(ball_max_pressure(g_tight, r_tight.max_ball_load_N))
