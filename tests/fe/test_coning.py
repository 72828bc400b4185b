"""Coning (``hdwf.fe.coning``): slice pushes, the re-sized cam, and the common twist of slices
in parallel (on analytic slices: no FE solve, milliseconds; the FE slices in
``test_coning_fe.py``)."""

import numpy as np
import pytest

from hdwf.drive.geometry import ARCMIN, drive_geometry
from hdwf.fe import coning
from hdwf.fe.coning import coned_geometry, slice_pushes, twist_at_torque
from hdwf.fe.solver import ContactFailure

NOMINAL = (31.0, 42.0, 0.015, 0.0, 0.0)


def test_pushes_grow_from_the_diaphragm_end():
    np.testing.assert_allclose(slice_pushes(0.2, 4), [1.025, 1.075, 1.125, 1.175])
    np.testing.assert_allclose(slice_pushes(0.0, 3), [1.0, 1.0, 1.0])


def test_unit_push_is_the_design_cam_and_the_push_scales_the_major_radius():
    g = drive_geometry("hd42", *NOMINAL, interference_m=0.1, tip_relief=1.1)
    same = coned_geometry(g, 1.0)
    assert (same.cam_A, same.cam_B) == (g.cam_A, g.cam_B)
    more = coned_geometry(g, 1.1)
    w0 = g.module * (g.z_cs - g.z_fs) / 2
    assert more.cam_A + more.cam_B - (g.cam_A + g.cam_B) == pytest.approx(0.1 * w0, rel=1e-9)
    assert more.r_fs_tip == g.r_fs_tip and more.interference_m == g.interference_m


def _parallel(K1, K2, b):
    """Two slices in parallel on one twist: one without backlash (K1), one with backlash b (K2)."""
    def torque_at(theta):
        return 0.5 * (K1 * theta + K2 * np.sign(theta) * max(0.0, abs(theta) - b))
    return torque_at


@pytest.mark.parametrize("T", [50.0, -50.0, 960.0, -960.0, 3000.0])
def test_twist_at_torque_is_exact_on_piecewise_linear_slices(T):
    """At T the common twist solves (K1 theta + K2 max(0, theta - b)) / 2 = T (one side or the
    other of the second slice's backlash, by the torque: +-50 N mm stays inside it, 2T/K1 = 0.17
    arcmin against b = 0.3; +-960 and 3000 N mm go beyond)."""
    K1, K2, b = 2.0e6, 3.0e6, 0.3 * ARCMIN
    theta, evaluations = twist_at_torque(_parallel(K1, K2, b), T, coning.FIRST_STEP)
    th1 = 2 * abs(T) / K1                      # the stiff slice alone
    expect = th1 if th1 <= b else (2 * abs(T) + K2 * b) / (K1 + K2)
    assert (th1 <= b) == (abs(T) < 100.0)        # both branches are tested
    assert theta == pytest.approx(np.sign(T) * expect, abs=coning.THETA_TOL)
    assert evaluations < coning.MAX_EVALUATIONS


def test_twist_at_torque_crosses_a_backlash_first():
    """A slice with play 2b (no torque inside it) then stiffness K: theta(T) = b + T / K, the
    play many first steps wide."""
    K, b = 2.0e6, 1.5 * ARCMIN

    def torque_at(theta):
        return K * np.sign(theta) * max(0.0, abs(theta) - b)

    theta, _ = twist_at_torque(torque_at, 960.0, coning.FIRST_STEP)
    assert theta == pytest.approx(b + 960.0 / K, abs=coning.THETA_TOL)


def test_twist_at_torque_that_is_never_reached_fails():
    """A relation that saturates below the torque: a failure, no number."""
    with pytest.raises(ContactFailure, match="not reached"):
        twist_at_torque(lambda theta: 500.0 * np.tanh(theta / ARCMIN), 960.0, coning.FIRST_STEP)
