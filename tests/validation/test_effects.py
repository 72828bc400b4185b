"""The candidate effects as changes to the FE model, each against a law it must obey."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hdwf.drive.geometry import drive_geometry
from hdwf.drive.mesh import build_mesh
from hdwf.fe import ModelChanges, solve_lost_motion, solve_lost_motion_variants
from hdwf.validation.effects import model_changes, parse_assignment, registry
from hdwf.validation.effects.oldham_play import ARCSEC
from hdwf.validation.effects.thermal import ALPHA_STEEL

ARCMIN = math.pi / (180 * 60)


@pytest.fixture(scope="module")
def drive():
    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.005, 0.005)
    return g, build_mesh(g, 5, 3, 1.0, symmetry="half")


@pytest.fixture(scope="module")
def baseline(drive):
    r = solve_lost_motion(*drive, steps_per_ramp=5)
    assert r.status == "ok", r.reason
    return r


def _solve(drive, **changes):
    r = solve_lost_motion(*drive, steps_per_ramp=5, changes=ModelChanges(**changes))
    assert r.status == "ok", r.reason
    return r


def test_registry_has_five_documented_effects():
    reg = registry()
    assert {"tooth_friction", "fs_cup_torsion", "cs_housing", "thermal", "oldham_play"} <= set(reg)
    for eff in reg.values():
        assert eff.description and eff.signature and eff.parameters
        for p in eff.parameters:
            assert p.lower <= p.realistic <= p.upper and p.unit
            assert all(p.lower <= v <= p.upper for _, v in p.realistic_by_unit)
        # at a realistic value the effect changes the model
        assert model_changes({eff.name: {p.name: p.realistic for p in eff.parameters}}) != ModelChanges()


def test_cup_stiffness_scales_with_size_cubed():
    """K = 2 pi G R^3 t / L with R, t, L in proportion to the drive: K(HD 120) / K(HD 42) =
    (120/42)^3 (bearing outside diameters, paper Table 2)."""
    p = registry()["fs_cup_torsion"].param("K_Nm_per_rad")
    assert p.realistic_for("hd42") == p.realistic
    assert p.realistic_for("hd120") / p.realistic_for("hd42") == pytest.approx((120 / 42) ** 3, rel=0.05)


def test_bad_effect_settings_are_refused_with_names():
    with pytest.raises(ValueError, match="outside"):
        model_changes({"thermal": {"delta_T_K": 99}})
    with pytest.raises(ValueError, match="missing"):
        model_changes({"thermal": {}})
    with pytest.raises(KeyError, match="unknown effect"):
        model_changes({"warp_drive": {"x": 1}})
    with pytest.raises(ValueError, match="NAME:PARAM=VALUE"):
        parse_assignment("thermal=3")


@pytest.mark.slow
def test_series_elements_add_exactly(drive, baseline):
    """A spring in series adds T/K at each end of the test (Φ + 2 T/K); a dead band adds its
    width to Φ; neither changes the contact solution."""
    K = 6.0e4                     # N m / rad
    play = 10.0                   # arcsec
    ch = model_changes({"fs_cup_torsion": {"K_Nm_per_rad": K}, "oldham_play": {"play_arcsec": play}})
    r = solve_lost_motion(*drive, steps_per_ramp=5, changes=ch)
    T = drive[0].torque / 1000.0  # N m
    expected = baseline.lost_motion_arcmin + (2 * T / K + play * ARCSEC) / ARCMIN
    assert r.lost_motion_arcmin == pytest.approx(expected, abs=1e-9)
    assert r.teeth_in_contact == baseline.teeth_in_contact


@pytest.mark.slow
def test_stiff_housing_is_the_clamped_rim(drive, baseline):
    """Springs of 1e9 N/mm² on the CS rim are a clamp to within 1e-6 of Φ; soft ones add compliance."""
    stiff = _solve(drive, cs_rim_stiffness_N_mm2=1e9)
    assert stiff.lost_motion_arcmin == pytest.approx(baseline.lost_motion_arcmin, rel=1e-6)
    soft = _solve(drive, cs_rim_stiffness_N_mm2=3e3)
    assert soft.phi_plus_arcmin > baseline.phi_plus_arcmin * 1.02


@pytest.mark.slow
def test_housing_compliance_follows_the_elastic_foundation_law(drive, baseline):
    """A ring on an elastic foundation deflects as k^-3/4 (Hetényi): a tenfold softer housing
    adds 10^0.75 = 5.6 times the lost motion, not 10 times. The calibration tabulates the
    housing in t = k^-0.75 for that reason; with t = 1/k its spline would be far from straight
    (a 7 % bias of the calibrated k at zero noise, benchmarks/bench_detectability.py)."""
    added = {k: _solve(drive, cs_rim_stiffness_N_mm2=k).lost_motion_arcmin - baseline.lost_motion_arcmin
             for k in (1e3, 1e4)}
    p = registry()["cs_housing"].param("k_N_per_mm2")
    assert added[1e3] / added[1e4] == pytest.approx(p.to_t(1e3) / p.to_t(1e4), rel=0.05)


def test_transformed_parameter_round_trip_and_uncertainty():
    """value -> t -> value is the identity, and sd(value) = |dvalue/dt| sd(t) (checked against
    a central difference) for the linear, 1/k and k^-3/4 transforms."""
    reg = registry()
    for p in (reg["tooth_friction"].param("mu"), reg["fs_cup_torsion"].param("K_Nm_per_rad"),
              reg["cs_housing"].param("k_N_per_mm2")):
        v = p.realistic
        t = p.to_t(v)
        assert p.from_t(t) == pytest.approx(v, rel=1e-12)
        h = 1e-6 * abs(t)
        slope = (p.from_t(t + h) - p.from_t(t - h)) / (2 * h)
        assert p.sd_from_t(t, 1e-3 * t) == pytest.approx(abs(slope) * 1e-3 * t, rel=1e-6)


@pytest.mark.slow
def test_thermal_growth_closes_the_flank_clearance(drive, baseline):
    """FS warmer by dT: its teeth move out by alpha dT r, which closes each flank's circumferential
    clearance by alpha dT r tan(alpha_tip) (contact at the FS tip, whose pressure angle is
    arccos(r_base / r_tip)); both flanks: dPhi = -2 alpha dT tan(alpha_tip) rad."""
    g = drive[0]
    dT = 10.0
    hot = solve_lost_motion(*drive, steps_per_ramp=5, changes=model_changes({"thermal": {"delta_T_K": dT}}))
    alpha_tip = math.acos(g.r_fs_base / g.r_fs_tip)
    expected = -2 * ALPHA_STEEL * dT * math.tan(alpha_tip) / ARCMIN
    assert hot.lost_motion_arcmin - baseline.lost_motion_arcmin == pytest.approx(expected, rel=0.05)
    # the elastic part at +T is untouched
    assert hot.phi_plus_arcmin == pytest.approx(baseline.phi_plus_arcmin, rel=0.01)


@pytest.mark.slow
def test_friction_dissipates_and_vanishes_at_zero(drive, baseline):
    """mu = 0 is the frictionless model; mu > 0 opens a loop that dissipates energy: on the
    positive half, the unloading branch lies above the loading branch at every torque
    (Coulomb friction resists the motion both ways). The width is not monotone in mu (more
    friction also means more sticking, which dissipates nothing), so only its sign is a law."""
    zero = _solve(drive, flank_friction=0.0)
    assert np.array_equal(zero.twist_arcmin, baseline.twist_arcmin)
    widths = []
    for mu in (0.1, 0.2):
        r = _solve(drive, flank_friction=mu)
        tw = r.twist_arcmin
        load, unload = tw[1:5], tw[9:5:-1]      # same torques 0.2..0.8 T on the way up and down
        assert (unload - load > 0).all(), (mu, load, unload)
        widths.append(float((unload - load).mean()))
    assert min(widths) > 0


@pytest.mark.slow
def test_shared_variants_equal_separate_solves(drive):
    """The campaign tables come from ``solve_lost_motion_variants`` (one mounted wave
    generator, a kept CS factorisation for a pure thermal scaling): each variant must give the
    curve a separate ``solve_lost_motion`` gives, to round-off."""
    variants = [ModelChanges(),
                model_changes({"thermal": {"delta_T_K": 20.0}}),
                model_changes({"thermal": {"delta_T_K": -30.0}}),
                model_changes({"cs_housing": {"k_N_per_mm2": 3.0e3}}),
                model_changes({"tooth_friction": {"mu": 0.1}})]
    shared = solve_lost_motion_variants(*drive, 5, variants)
    for ch, res in zip(variants, shared):
        alone = solve_lost_motion(*drive, steps_per_ramp=5, changes=ch)
        assert res.status == alone.status == "ok", (res.reason, alone.reason)
        np.testing.assert_allclose(res.twist_arcmin, alone.twist_arcmin, rtol=0, atol=1e-8)
