"""Coning on FE slices (``hdwf.fe.coning.solve_coned``): the studies' model (0.3 m preload on a
3900 m flank layer) of one HD 42 design on the coarse half mesh (5 x 3 elements per tooth)."""

from dataclasses import replace

import numpy as np
import pytest

from hdwf.drive.geometry import ARCMIN, drive_geometry
from hdwf.drive.mesh import build_mesh
from hdwf.fe import solve_lost_motion
from hdwf.fe.changes import ModelChanges
from hdwf.fe.coning import THETA_TOL, solve_coned

COARSE = {"elements_over_height": 5, "elements_over_thickness": 3}
STUDIES = ModelChanges(flank_interference_m=0.3, flank_layer_m=3900.0)   # config.yaml's fe.effects
DESIGN = ("hd42", 31.0014, 41.9982, 0.01113, 0.01597, 0.00244)          # our LHS design hd42-lhs-01


@pytest.mark.slow
def test_one_uniform_slice_is_the_section_and_the_slice_count_converges():
    """c = 0 on one slice is the plain section: the same settled states at +-T, found by
    prescribing the twist instead of the torque, so Phi agrees to the twist tolerance on each
    side. With coning (c = 0.2) the slices in parallel give Phi within 1 % from N = 2 to 4.
    In the model (``ModelChanges.coning_slope``), one slice of a vanishing slope runs the
    section's test level by level, and two slices at c = 0.2 give ``solve_coned``'s Phi."""
    g = drive_geometry(*DESIGN, **STUDIES.geometry_part())
    mesh = build_mesh(g, **COARSE, symmetry="half")
    section = solve_lost_motion(g, mesh, steps_per_ramp=2, changes=STUDIES)
    one, two, four = solve_coned(g, mesh, [(0.0, 1), (0.2, 2), (0.2, 4)], changes=STUDIES)
    assert section.status == one.status == two.status == four.status == "ok"
    assert one.lost_motion_arcmin == pytest.approx(section.lost_motion_arcmin, abs=2 * THETA_TOL / ARCMIN)
    assert four.lost_motion_arcmin == pytest.approx(two.lost_motion_arcmin, rel=0.01)
    assert four.lost_motion_arcmin > 1.02 * one.lost_motion_arcmin     # the open end has play

    uniform = solve_lost_motion(g, mesh, steps_per_ramp=2,
                                changes=replace(STUDIES, coning_slope=1e-12, coning_slices=1))
    coned = solve_lost_motion(g, mesh, steps_per_ramp=1, changes=replace(STUDIES, coning_slope=0.2, coning_slices=2))
    assert uniform.status == coned.status == "ok"
    # every level to the twist tolerance (the zero-torque ones at 1e-3 T: the section reaches them
    # unloading, the coned test from zero twist, so within the span of that torque's twist too)
    np.testing.assert_allclose(uniform.twist_arcmin, section.twist_arcmin, atol=3 * THETA_TOL / ARCMIN)
    assert (uniform.teeth_in_contact, uniform.loaded_arc_deg) == (section.teeth_in_contact, section.loaded_arc_deg)
    assert coned.lost_motion_arcmin == pytest.approx(two.lost_motion_arcmin, abs=2 * THETA_TOL / ARCMIN)
    # the section re-finds its tooth pairs from scratch at +-T; the coned slices keep their settled
    # gaps, so their record says the check was not made rather than give a number that reads as passed
    assert 0.0 <= section.max_penetration_redetected_um < 0.5
    assert np.isnan(coned.max_penetration_redetected_um) and "not checked" in coned.notes


def test_friction_is_refused_with_a_reason():
    """A prescribed twist is solved frictionless only: flank friction fails every case with
    its reason, no number."""
    g = drive_geometry(*DESIGN)
    mesh = build_mesh(g, **COARSE, symmetry="half")
    (out,) = solve_coned(g, mesh, [(0.0, 1)], changes=ModelChanges(flank_friction=0.1))
    assert out.status == "failed" and "frictionless" in out.reason
    assert out.lost_motion_arcmin != out.lost_motion_arcmin          # NaN
