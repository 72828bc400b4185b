"""Preloaded tooth engagement (``interference_m``): the wedge it makes, the ramp that mounts it.

Coarse half meshes (5 x 3 elements per tooth) keep each test to seconds; the full-model
comparison is marked slow.
"""

import math
from functools import cache

import numpy as np
import pytest

from hdwf.drive.geometry import ARCMIN, drive_geometry, fs_half_angle, geometric_backlash_arcmin
from hdwf.drive.mesh import build_mesh
from hdwf.fe import LostMotionModel, preload, solve_lost_motion
from hdwf.fe.contact_rows import stack_rows, tooth_rows
from hdwf.fe.cycle import mount_wave_generator

COARSE = {"elements_over_height": 5, "elements_over_thickness": 3}
NOMINAL = ("hd42", 31.0, 42.0, 0.015, 0.0, 0.0)      # Table 3 nominal: zero offsets


def test_interference_is_a_thickness_allowance():
    """interference_m * m thickens every FS flank by a normal offset: the same outline as
    r_FS lowered by that much; 0 leaves the geometry as it was; negative values are refused."""
    m = 0.18
    a = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.02, 0.0, interference_m=0.1)
    b = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.02 - 0.1 * m, 0.0)
    r = np.linspace(a.r_fs_root, a.r_fs_tip, 7)
    assert np.allclose(fs_half_angle(a, r), fs_half_angle(b, r), rtol=0, atol=1e-15)
    assert a.interference == pytest.approx(0.018)
    assert geometric_backlash_arcmin(a) == pytest.approx(geometric_backlash_arcmin(b), rel=1e-12)
    assert drive_geometry(*NOMINAL) == drive_geometry(*NOMINAL, interference_m=0.0)
    with pytest.raises(ValueError):
        drive_geometry(*NOMINAL, interference_m=-0.1)


@cache
def _wedge_model(interference_m):
    """Flanks in 16 chords (a chord's angle is the flank's within 0.08 deg), teeth watched
    near the major axis only (no solve: the outlines and the detection)."""
    g = drive_geometry(*NOMINAL, interference_m=interference_m)
    mesh = build_mesh(g, elements_over_height=16, elements_over_thickness=3, symmetry="half")
    return g, LostMotionModel(g, mesh, zone_deg=3.0)


def _major_axis_gap(model, g, shift):
    """Re-detected (nonlinear) gap of the FS flank node of the major-axis tooth nearest the
    pitch circle, with the FS moved rigidly out by ``shift`` (mm) and nothing else moved."""
    fs = model.bodies["fs"]
    u = np.zeros(model.nwatch)
    u[fs.watch_index[0, fs.watch_nodes]] = shift
    rows = tooth_rows(model.structure, g, u, np.inf)
    sn = rows.slave_nodes[0]
    x = fs.x[:, sn]
    near_axis = np.abs(np.arctan2(x[1], x[0])) < math.pi / g.z_fs
    j = np.flatnonzero(near_axis)[np.argmin(np.abs(np.hypot(*x[:, near_axis]) - g.r_fs_pitch))]
    return float((rows.g0 + rows.G @ u)[j])


@pytest.mark.slow
def test_rigid_wedge_offset_delta_needs_radial_motion_delta_over_sin_alpha():
    """A rigid wedge: the major-axis FS tooth pushed out rigidly by w0 = m sits in its CS
    space overlapping it by the interference delta at the pitch point (both involutes
    there at the pressure angle).  Moving it back along the axis opens the flank at the
    rate sin(alpha - theta_P): the flank's pitch point lies theta_P = pi m / (4 r_p) =
    0.375 deg off the axis.  So the overlap is gone after about delta / sin(alpha) (here
    0.1 m = 18 um -> 52.6 um); a little later, because the flank sliding towards the CS
    tip meets smaller pressure angles (0.35 deg less after 50 um).  Checked on the meshed
    outlines (flanks in 16 chords, each turning 0.15 deg) with the solver's detection."""
    g, model = _wedge_model(0.1)
    delta, alpha = g.interference, g.alpha
    theta_p = math.pi * g.module / (4 * g.r_fs_pitch)
    assert _major_axis_gap(model, g, g.w0) == pytest.approx(-delta, abs=0.2e-3)
    h = 1e-3
    rate = (_major_axis_gap(model, g, g.w0 - h) - _major_axis_gap(model, g, g.w0)) / h
    assert rate == pytest.approx(math.sin(alpha - theta_p), rel=0.006)
    x0, x1 = delta / math.sin(alpha), 1.1 * delta / math.sin(alpha)    # secant on the gap
    g0, g1 = _major_axis_gap(model, g, g.w0 - x0), _major_axis_gap(model, g, g.w0 - x1)
    closing = x0 - g0 * (x1 - x0) / (g1 - g0)
    assert 1.0 < closing / (delta / math.sin(alpha)) < 1.04


def _mounted(interference_m, ramp_step_m=None, monkeypatch=None):
    g = drive_geometry(*NOMINAL, interference_m=interference_m)
    if ramp_step_m is not None:
        monkeypatch.setattr(preload, "RAMP_STEP_M", ramp_step_m)
    model = LostMotionModel(g, build_mesh(g, **COARSE, symmetry="half"), zone_deg=90.0)
    return g, model, mount_wave_generator(model, ramp_teeth=True)


def _tooth_force(model, mounted, g):
    """Resultant contact force (N) on the major-axis FS tooth: its half at angle 0 plus,
    turned by pi, the half of its image at angle pi (the half model's other half)."""
    fs = model.bodies["fs"]
    forces = stack_rows(model.rows).G.T @ mounted.solution.normal_force
    wn = np.intersect1d(fs.watch_nodes, fs.body_mesh.node_sets["fs_teeth"])   # not the bore
    th = np.arctan2(fs.x[1, wn], fs.x[0, wn])
    f = np.vstack([forces[fs.watch_index[0, wn]], forces[fs.watch_index[1, wn]]])
    half_pitch = math.pi / g.z_fs
    at0, atpi = np.abs(th) < half_pitch, np.abs(th - math.pi) < half_pitch
    total = f[:, at0].sum(axis=1) - f[:, atpi].sum(axis=1)
    magnitude = np.hypot(*f[:, at0]).sum() + np.hypot(*f[:, atpi]).sum()
    return total, magnitude


@pytest.mark.slow
def test_preloaded_wedge_force_balance_and_true_gap():
    """The mounted preloaded drive (0.1 m): no tooth pair re-detected at its true gap
    penetrates more than 0.06 um; the major-axis tooth is a balanced wedge: its two flanks
    push it radially inwards with no tangential resultant (the drive is mirror-symmetric
    about the major axis), and the radial resultant is the flank forces times the sine of
    the pressure angle along the engaged flanks (14-28 deg from root to tip)."""
    g, model, mounted = _mounted(0.1)
    assert mounted.preload["penetration_um"] < 0.06
    assert mounted.preload["overlap_um"] > 0.9 * g.interference * 1000
    force, magnitude = _tooth_force(model, mounted, g)
    assert force[0] < 0 and magnitude > 1.0        # N: pressed in, a real preload
    assert abs(force[1]) < 0.02 * abs(force[0])
    assert math.sin(math.radians(14)) < abs(force[0]) / magnitude < math.sin(math.radians(28))
    # the wedge pushes the FS back towards the axis, by at most the rigid wedge's
    # delta / sin(alpha) (52.6 um): the teeth give a little, the wave generator most
    retreat = mounted.preload["wg_retreat_um"]
    assert 0.5 * 52.6 < retreat < 52.6


@pytest.mark.slow
def test_a_ramp_that_cycles_is_cut_back_to_the_state_of_a_finer_ramp(monkeypatch):
    """A preload ramp whose active-set iteration cycles (HD 120 Table 5 set 14 at 0.169 m on
    the campaigns' coarse mesh did, in one step of 16 um) is ramped again from the wave
    generator's state in steps half as large: the same mount as a ramp run at that step
    from the start (the same FS deflection, the iterations of the failed ramp counted);
    after ``RAMP_CUTBACKS`` halvings the failure is reported."""
    real = preload.mount_preloaded
    calls = []

    def cycling_first(model, level, step):
        calls.append(step)
        if len(calls) == 1:
            model.solver.iterations += 200          # as an active set that cycled to max_iter
            raise preload.ContactFailure("active-set iteration did not converge")
        return real(model, level, step)

    monkeypatch.setattr(preload, "mount_preloaded", cycling_first)
    g, model, cut = _mounted(0.1)
    assert calls == [preload.RAMP_STEP_M, preload.RAMP_STEP_M / 2]
    assert cut.preload["ramp_cutbacks"] == 1
    assert model.iterations > 200
    monkeypatch.setattr(preload, "mount_preloaded", real)
    _, _, finer = _mounted(0.1, ramp_step_m=preload.RAMP_STEP_M / 2, monkeypatch=monkeypatch)
    assert finer.preload["ramp_cutbacks"] == 0
    assert cut.preload["ramp_steps"] == finer.preload["ramp_steps"]
    assert cut.deflection_um == pytest.approx(finer.deflection_um, abs=1e-9)

    def always_cycling(model, level, step):
        raise preload.ContactFailure("active-set iteration did not converge")

    monkeypatch.setattr(preload, "mount_preloaded", always_cycling)
    r = solve_lost_motion(g, build_mesh(g, **COARSE, symmetry="half"), steps_per_ramp=1)
    assert r.status == "failed" and "did not converge" in r.reason


@pytest.mark.slow
def test_preload_ramp_converges_to_the_same_state(monkeypatch):
    """The mounted state does not depend on the ramp: 0.05 m per step (the default) and
    0.02 m per step give the same FS deflection at the major axis within the ramp's
    tolerance on the gaps (0.05 um)."""
    _, _, a = _mounted(0.1)
    _, _, b = _mounted(0.1, ramp_step_m=0.02, monkeypatch=monkeypatch)
    assert b.preload["ramp_steps"] > a.preload["ramp_steps"]
    assert a.deflection_um == pytest.approx(b.deflection_um, abs=preload.GEO_TOL * 1000)


@cache
def _unpreloaded_every_tooth_arcmin() -> float:
    """Phi of the nominal design without preload, every tooth watched as a preload watches them
    (0.0671 arcmin on the coarse half mesh)."""
    g = drive_geometry(*NOMINAL)
    r = solve_lost_motion(g, build_mesh(g, **COARSE, symmetry="half"), steps_per_ramp=1, zone_deg=90.0)
    assert r.status == "ok", r.reason
    return r.lost_motion_arcmin


@pytest.mark.slow
@pytest.mark.parametrize("interference_m", [0.1, 0.3])
def test_preloaded_lost_motion_solves_and_is_small(interference_m):
    """Up to 0.3 m the test solves (status ok) with the true gap re-detected at +-T, and the
    preloaded drive has far less lost motion than the same design without preload (less than
    half; a preload lost between geometry and mesh would leave it equal)."""
    g = drive_geometry(*NOMINAL, interference_m=interference_m)
    r = solve_lost_motion(g, build_mesh(g, **COARSE, symmetry="half"), steps_per_ramp=1)
    assert r.status == "ok", r.reason
    assert r.max_penetration_redetected_um < 0.06
    assert 0 < r.lost_motion_arcmin < 0.5 * _unpreloaded_every_tooth_arcmin()
    if interference_m == 0.1:   # the full model gives 0.015908 (test_preloaded_half_model_equals_full_model)
        assert r.lost_motion_arcmin == pytest.approx(0.0159, abs=0.0033)   # 2 x 0.01 um gap tolerance / r_b
    assert "preload ramp" in r.notes
    assert r.overlap_outside_zones_um == 0.0       # every tooth is watched


def test_teeth_outside_the_zones_are_checked():
    """Today's 35 deg zones leave teeth unsolved: the result reports how far they overlap at
    the mount instead of hiding it.  On the nominal HD 42 design CS tip corners 55-70 deg
    from the major axis sink 24 um into FS flanks (docs/fe-model.md); Phi is today's."""
    g = drive_geometry(*NOMINAL)
    r = solve_lost_motion(g, build_mesh(g, **COARSE, symmetry="half"), steps_per_ramp=1)
    assert r.status == "ok", r.reason
    assert r.overlap_outside_zones_um == pytest.approx(24.0, rel=0.05)
    assert "outside the solved zones overlap by" in r.notes


@pytest.mark.slow
def test_preloaded_half_model_equals_full_model():
    """With the preload on (0.1 m) the half model gives the full model's Phi, phi and
    phi' within 0.5 % of Phi plus 0.001 arcmin (two different gmsh meshes; Phi is small),
    and the same preloaded mount.  Measured: Phi 0.015908 (full) / 0.015914 (half) arcmin,
    FS deflection at the major axis 129.092 / 129.095 um; solves 30 s / 8 s."""
    g = drive_geometry(*NOMINAL, interference_m=0.1)
    full = solve_lost_motion(g, build_mesh(g, **COARSE), steps_per_ramp=1)
    half = solve_lost_motion(g, build_mesh(g, **COARSE, symmetry="half"), steps_per_ramp=1)
    assert full.status == "ok" and half.status == "ok", (full.reason, half.reason)
    tol = 0.005 * full.lost_motion_arcmin + 0.001
    for attr in ("lost_motion_arcmin", "phi_plus_arcmin", "phi_minus_arcmin"):
        assert getattr(half, attr) == pytest.approx(getattr(full, attr), abs=tol), attr
    assert half.wg_deflection_um == pytest.approx(full.wg_deflection_um, abs=0.05)


@pytest.mark.slow
def test_preloaded_variants_share_a_mount_only_across_series_elements():
    """With a preload, variants that differ only in series elements (the output play here)
    share one mount and torque sequence: the same rim twist, the play added on the output;
    each equals its own ``solve_lost_motion``."""
    from hdwf.fe.changes import ModelChanges
    from hdwf.fe.cycle import solve_lost_motion_variants
    g = drive_geometry(*NOMINAL, interference_m=0.05)
    mesh = build_mesh(g, symmetry="half", **COARSE)
    plain, play = ModelChanges(), ModelChanges(output_play_rad=1e-4)
    a, b = solve_lost_motion_variants(g, mesh, 2, [plain, play])
    assert a.status == b.status == "ok"
    alone = solve_lost_motion(g, mesh, 2, changes=play)
    assert np.allclose(b.twist_arcmin, alone.twist_arcmin, rtol=0, atol=1e-9)
    plain_alone = solve_lost_motion(g, mesh, 2, changes=plain)
    assert np.allclose(a.twist_arcmin, plain_alone.twist_arcmin, rtol=0, atol=1e-9)
    # a dead band in series adds exactly its width to Phi (1e-4 rad = 0.3438 arcmin)
    assert b.lost_motion_arcmin - a.lost_motion_arcmin == pytest.approx(1e-4 / ARCMIN, abs=1e-9)


@pytest.mark.slow
def test_preloaded_twist_is_settled_at_plus_and_minus_torque():
    """A preloaded section without play (hd42-lhs-09 of the default study, 0.147 m, relief
    1.1, the studies' mesh and 5 steps per ramp) is mirror-symmetric, so phi = phi' up to mesh
    asymmetry, and its Phi does not depend on the load path.  With the tooth rows
    re-linearised once at +T and kept, phi was 0.182 and phi' 0.055 arcmin and the curve came
    back to 0.040 (docs/fe-model.md, "Gaps at +-T"); settled: 0.178 and 0.179."""
    g = drive_geometry("hd42", 31.0021891, 41.9841730, 0.0095806475, 0.0038795075, 0.0105284616,
                       interference_m=0.147, tip_relief=1.1)
    mesh = build_mesh(g, 10, 6, symmetry="half")
    r = solve_lost_motion(g, mesh, steps_per_ramp=5)
    assert r.status == "ok", r.reason
    assert r.phi_plus_arcmin == pytest.approx(r.phi_minus_arcmin, rel=0.03)
    # frictionless, Phi does not depend on the load path: one step per ramp (other warm starts,
    # other iterates) settles at the same states within the 0.01 um gap tolerance
    # (2 x 0.01 um over the CS base radius, 21 mm: 0.0033 arcmin)
    one = solve_lost_motion(g, mesh, steps_per_ramp=1)
    assert one.status == "ok", one.reason
    assert one.lost_motion_arcmin == pytest.approx(r.lost_motion_arcmin, abs=0.0033)


def test_frictionless_way_back_passes_through_the_way_up():
    """Frictionless, a level on the way back is the problem of the way up at that torque (the
    mount's rows, the same load: elastic contact without friction has one solution), so it is
    not solved again and the curve comes back through the same points; solved again from
    another warm start it would differ within the gap tolerance (0.4967 against 0.4971 arcmin
    at 0.8 T on Table 4 set 8).  With flank friction nothing is reused (next test)."""
    g = drive_geometry(*NOMINAL, interference_m=0.05)
    r = solve_lost_motion(g, build_mesh(g, **COARSE, symmetry="half"), steps_per_ramp=2)
    assert r.status == "ok", r.reason
    tw = r.twist_arcmin                      # 0, T/2, T, T/2, 0, -T/2, -T, -T/2, 0
    assert tw[3] == tw[1] and tw[4] == tw[0] and tw[7] == tw[5]
    assert tw[8] != tw[0]                    # -0 is its own level (the bias towards -T)


@pytest.mark.slow
def test_flank_friction_is_switched_on_at_the_assembled_preload():
    """A drive is assembled axially, so its preloaded flanks keep no tangential force in the
    section's plane: the teeth are ramped in without friction, which then holds the flanks
    where they are. The mounted state is the frictionless one exactly (wave-generator push,
    most loaded ball), the test solves at mu 0.1 (ramped in with friction, 7 of 54 paper_hd42
    specimens at 0.22 m failed at the mount), and as mu -> 0 the lost motion tends to the
    frictionless one: mu = 1e-4 within 0.001 arcmin (a third of the gap tolerance's 0.0033)."""
    from hdwf.fe.changes import ModelChanges
    g = drive_geometry(*NOMINAL, **ModelChanges(flank_interference_m=0.05).geometry_part())
    mesh = build_mesh(g, **COARSE, symmetry="half")
    plain, slight, mu01 = (solve_lost_motion(g, mesh, steps_per_ramp=1,
                                             changes=ModelChanges(flank_interference_m=0.05, flank_friction=mu))
                           for mu in (0.0, 1e-4, 0.1))
    for r in (plain, slight, mu01):
        assert r.status == "ok", r.reason
    assert mu01.wg_deflection_um == pytest.approx(plain.wg_deflection_um, rel=1e-9, abs=0)   # round-off
    assert mu01.max_ball_load_N == pytest.approx(plain.max_ball_load_N, rel=1e-9, abs=0)
    assert slight.lost_motion_arcmin == pytest.approx(plain.lost_motion_arcmin, abs=0.001)
    assert mu01.lost_motion_arcmin < plain.lost_motion_arcmin - 0.01    # sticking flanks hold the twist back


@pytest.mark.slow
def test_friction_variants_share_the_frictionless_mount(monkeypatch):
    """Friction acts only from the assembled state on, so variants of a preloaded design that
    differ in their flank friction only are solved on forks of one frictionless mount, each
    with its friction switched on there: the same numbers as each variant mounted on its own
    (to round-off), and one wave-generator mount instead of one per friction value."""
    from hdwf.fe import ModelChanges, solve_lost_motion_variants
    from hdwf.fe import cycle

    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.005, 0.005, interference_m=0.1, tip_relief=1.1)
    mesh = build_mesh(g, **COARSE, symmetry="half")
    variants = [ModelChanges(flank_interference_m=0.1, flank_friction=mu) for mu in (0.0, 0.05, 0.1)]
    mounts = []
    real_mount = cycle.mount_wave_generator

    def counting_mount(model, ramp_teeth=False):
        mounts.append(model.changes)
        return real_mount(model, ramp_teeth)
    monkeypatch.setattr(cycle, "mount_wave_generator", counting_mount)
    together = solve_lost_motion_variants(g, mesh, 1, variants)
    monkeypatch.undo()
    assert mounts == [ModelChanges(flank_interference_m=0.1)]
    for ch, r in zip(variants, together):
        alone = solve_lost_motion(g, mesh, steps_per_ramp=1, changes=ch)
        assert r.status == alone.status == "ok", (r.reason, alone.reason)
        np.testing.assert_allclose(r.twist_arcmin, alone.twist_arcmin, rtol=0, atol=1e-9)
    assert together[2].lost_motion_arcmin < together[0].lost_motion_arcmin - 0.01   # sticking flanks


def test_friction_is_the_only_change_a_mount_can_take_on():
    """``with_flank_friction`` switches friction on at a mounted state; a variant that differs
    in anything else needs its own mount, and asking for it is an error, not a silent reuse."""
    from types import SimpleNamespace

    from hdwf.fe import ModelChanges
    mounted = SimpleNamespace(changes=ModelChanges(flank_interference_m=0.1))
    with pytest.raises(ValueError, match="more than its flank friction"):
        preload.with_flank_friction(mounted, None, ModelChanges(flank_interference_m=0.15, flank_friction=0.1))


@pytest.mark.slow
def test_a_reused_level_leaves_the_warm_start_the_solved_one_left():
    """A level reused on the way back must hand the next level the warm start (displacement,
    ball secants) it left when it was solved, not that of the last level solved (+T).  From
    +T's, the -T level of HD 120 Table 5 set 10 at 0.05 m (coarse mesh, one step per ramp;
    the paper_hd120 campaign's grid) cycled to 200 iterations; solved again on the way back
    (no reuse) it gave phi 2.0596 and phi' 6.4020 arcmin."""
    g = drive_geometry("hd120", 90.0052963, 119.9971481, 0.034, 0.044444444, 0.043333333,
                       interference_m=0.05, tip_relief=1.1)
    r = solve_lost_motion(g, build_mesh(g, **COARSE, symmetry="half"), steps_per_ramp=1)
    assert r.status == "ok", r.reason
    assert r.phi_plus_arcmin == pytest.approx(2.0596, abs=0.0033)    # the gap tolerance, as above
    assert r.phi_minus_arcmin == pytest.approx(6.4020, abs=0.0033)


def test_a_deeper_cam_is_sized_to_push_kappa_w0():
    """deflection_coeff kappa sizes the cam so that the nominal bearing (rigid) pushes the FS
    bore out by kappa * w0 at the major axis: cam radius there = d_nom/2 + kappa w0 + G_r,nom/2.
    kappa = 1 is today's geometry; addendum_frac sets the tip/root clearance at w0, (1 - 2 a) h."""
    base = drive_geometry(*NOMINAL)
    deep = drive_geometry(*NOMINAL, deflection_coeff=1.4, addendum_frac=0.38)
    for g, kappa in ((base, 1.0), (deep, 1.4)):
        assert g.cam_radius(0.0) == pytest.approx(g.d_nom / 2 + kappa * g.w0 + g.Gr_nom / 2, abs=1e-9)
    assert drive_geometry(*NOMINAL, deflection_coeff=1.0) == base and not base.preloaded
    assert deep.preloaded
    assert deep.r_cs_root - (deep.r_fs_tip + deep.w0) == pytest.approx((1 - 2 * 0.38) * 0.337, abs=1e-12)
    # the major-axis pair overlaps by (kappa - 1) w0 sin(alpha) per flank (a locked pair: negative)
    overlap = 0.4 * deep.w0 * math.sin(deep.alpha)
    assert geometric_backlash_arcmin(deep) == pytest.approx(
        geometric_backlash_arcmin(drive_geometry(*NOMINAL, interference_m=overlap / deep.module)), rel=1e-12)
    # the relief is derived on the 2-tooth push's path only
    for bad in ({"deflection_coeff": 0.9}, {"deflection_coeff": float("nan")}, {"addendum_frac": 0.6},
                {"deflection_coeff": 1.2, "tip_relief": 1.1}):
        with pytest.raises(ValueError):
            drive_geometry(*NOMINAL, **bad)


def _rack_path_backlash_arcmin(g, kappa):
    """Rigid-body lost motion with a cam pushing kappa * w0 (w0 = m), on the rack path of
    ``hdwf.drive.relief``: the FS tooth at phi from the major axis sits (kappa cos 2 phi - 1) m
    deeper than full depth and (m/2)(2 phi - kappa k sin 2 phi) ahead of its CS space (k the
    tilt factor), so its flanks' normal gaps are r_FS + r_CS - (kappa cos 2 phi - 1) m sin(alpha)
    -+ s cos(alpha); a rigid turn closes them at r_b, and the first tooth to touch on each side
    sets the lost motion, 2 min(gap) / r_b.  For kappa > 1 that tooth is off the axis."""
    phi = 2 * math.pi * np.arange(-30, 31) / g.z_fs
    m, a = g.module, g.alpha
    s = 0.5 * m * (2 * phi - kappa * g.tilt_factor * np.sin(2 * phi))
    gap = g.r_fs + g.r_cs - (kappa * np.cos(2 * phi) - 1) * m * math.sin(a) - np.abs(s) * math.cos(a)
    return 2 * float(gap.min()) / g.r_cs_base / ARCMIN


@pytest.mark.parametrize("kappa", [1.0, 1.4])
def test_rigid_lost_motion_with_a_deeper_cam_follows_the_tooth_path(kappa):
    """E x 1e4 on an open design (r_FS = r_CS = 20 um): the twist is the rigid clearance the
    cam leaves.  kappa = 1.4 closes (kappa - 1) m sin(alpha) = 24.6 um per flank at the axis and
    more at the tooth 6-8 deg off it: 4.09 arcmin on the rack path against 13.32 at kappa = 1.
    The FE section (involutes, a ring that is not a rack) agrees within 3 % (measured 4.100
    and 13.548)."""
    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.020, 0.020, deflection_coeff=kappa,
                       addendum_frac=0.38)
    mesh = build_mesh(g, elements_over_height=6, elements_over_thickness=4, symmetry="half")
    r = solve_lost_motion(g, mesh, steps_per_ramp=1, E=g.E * 1e4)
    assert r.status == "ok", r.reason
    assert r.lost_motion_arcmin == pytest.approx(_rack_path_backlash_arcmin(g, kappa), rel=0.03)


def test_flank_layer_is_a_steel_layer_so_many_modules_thick():
    """c = thickness m / E: 1166.67 modules of HD 42 (m 0.18 mm) give 1 um per MPa."""
    from hdwf.fe.changes import ModelChanges
    assert ModelChanges(flank_layer_m=210.0 / 0.18).layer_um_per_MPa(0.18, 210_000.0) == pytest.approx(1.0)
    assert ModelChanges().layer_um_per_MPa(0.18, 210_000.0) == 0.0


def _flank_layer_stiffness(refinement: float, layer_um_per_MPa: float) -> float:
    """Sum of 1/s over the FS slave rows (every FS tooth of the half model, N/mm) on a mesh."""
    import dataclasses
    g = dataclasses.replace(drive_geometry(*NOMINAL, interference_m=0.1), flank_layer_um_per_MPa=layer_um_per_MPa)
    model = LostMotionModel(g, build_mesh(g, **COARSE, refinement=refinement, symmetry="half"), zone_deg=90.0)
    mounted = mount_wave_generator(model)
    rows = tooth_rows(model.structure, g, mounted.solution.u_watch, np.inf)
    return float(np.sum(1.0 / rows.compliance[:rows.slave_nodes[0].size]))


def test_flank_layer_stiffness_is_the_flank_area_over_c():
    """The layer is a constant compliance per unit area, spread over the nodes by their share of
    the flank: over the FS teeth the pairs' stiffnesses add up to face width x outline length / c
    on any mesh (1.5x finer: within 0.5 %), and halve when c doubles; the outline of the z/2
    teeth of the half model lies between z/2 twice the tooth height and z/2 pitches plus that."""
    coarse, fine = _flank_layer_stiffness(1.0, 1.0), _flank_layer_stiffness(1.5, 1.0)
    assert fine == pytest.approx(coarse, rel=0.005)
    assert _flank_layer_stiffness(1.0, 2.0) == pytest.approx(coarse / 2.0, rel=1e-12)
    g = drive_geometry(*NOMINAL)
    height, teeth = g.r_fs_tip - g.r_fs_root, g.z_fs / 2
    outline = coarse * 1e-3 / g.face_fs      # N/mm * mm/MPa / mm = mm of outline
    assert teeth * 2 * height < outline < teeth * (2 * height + 2 * math.pi * g.r_fs_pitch / g.z_fs)


@pytest.mark.slow
def test_flank_layer_softens_a_preloaded_drive_and_vanishes_with_c():
    """A preloaded drive (0.157 m) with a flank layer has more lost motion (the penetration check
    allows the layer's approach s p), a vanishing layer gives the drive without one, and the
    effect's parameter (``ModelChanges.flank_layer_m``) gives the same solve.  (At the edge of a
    contact the overlap integrated on a layer grows as sqrt(c) — the force of a corner sunk by
    d into it goes as d^2 — so 'vanishing' is 1e-9 um/MPa: 1e-6 leaves 0.02 um there.)"""
    import dataclasses
    g = drive_geometry(*NOMINAL, interference_m=0.157, tip_relief=1.1)
    mesh = build_mesh(g, **COARSE, symmetry="half")
    phi = {c: solve_lost_motion(dataclasses.replace(g, flank_layer_um_per_MPa=c), mesh, steps_per_ramp=1)
           for c in (0.0, 1e-9, 0.3)}
    assert all(r.status == "ok" for r in phi.values()), [r.reason for r in phi.values()]
    assert phi[1e-9].lost_motion_arcmin == pytest.approx(phi[0.0].lost_motion_arcmin, abs=1e-4)
    assert phi[0.3].lost_motion_arcmin > 2 * phi[0.0].lost_motion_arcmin
    from hdwf.fe.changes import ModelChanges   # the effect's way in: the same layer in modules
    via = solve_lost_motion(g, mesh, steps_per_ramp=1, changes=ModelChanges(flank_layer_m=0.3e-3 * g.E / g.module))
    assert via.lost_motion_arcmin == pytest.approx(phi[0.3].lost_motion_arcmin, abs=1e-9)
