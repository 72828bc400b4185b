"""Coning prototype (``hdwf.fe.coning``): slice pushes, the re-sized cam, and the parallel
combination of slice relations (on analytic slices: no FE solve, milliseconds)."""

import numpy as np
import pytest

from hdwf.drive.geometry import ARCMIN, drive_geometry
from hdwf.fe import coning
from hdwf.fe.coning import SliceCurve, coned_geometry, coupled_twist, slice_pushes

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


class _Analytic(SliceCurve):
    """A slice with backlash +-b and stiffness K beyond it (twist = b sign T + T / K)."""

    def __init__(self, K, b):
        super().__init__(push=1.0)
        self.K, self.b = K, b

    def solve(self, torque):
        th = np.sign(torque) * self.b + torque / self.K
        self.torque.append(float(torque))
        self.twist.append(float(th))
        self.levels += 1
        return float(th)


def test_parallel_combination_is_exact_on_piecewise_linear_slices():
    """Two slices, one with no backlash (K1), one with backlash b (K2): at +-T the common twist
    solves (K1 theta + K2 max(0, theta - b)) / 2 = T; the combination finds it."""
    T = 960.0
    K1, K2, b = 2.0e6, 3.0e6, 0.3 * ARCMIN
    slices = [_Analytic(K1, 0.0), _Analytic(K2, b)]
    for s in slices:
        for f in coning.SAMPLE_FRACTIONS:
            s.solve(f * T)
            s.solve(-f * T)
    theta, _ = coupled_twist(slices, T)
    th1 = 2 * T / K1                       # the stiff slice alone
    expect = th1 if th1 <= b else (2 * T + K2 * b) / (K1 + K2)
    assert theta == pytest.approx(expect, abs=coning.THETA_TOL)
    theta_m, _ = coupled_twist(slices, -T)
    assert theta_m == pytest.approx(-expect, abs=coning.THETA_TOL)


class _Crossed(_Analytic):
    """A locked slice whose two sides end in states that cross by ``c`` near zero torque:
    twist = T / K - c sign T (the -bias state lies above the +bias one), as a preloaded slice
    reached on separate paths from the mount does at the contact tolerance."""

    def __init__(self, K, c):
        super().__init__(K, -c)


def test_each_side_combines_its_own_relation():
    """A crossing of 2 THETA_TOL between the sides' bias states is no failure: at +T only the
    + side's states count. Two slices (K1 crossed, K2 with backlash b): at +T the common twist
    solves (K1 (theta + c) + K2 max(0, theta - b)) / 2 = T."""
    T = 960.0
    K1, K2, b, c = 2.0e6, 3.0e6, 0.3 * ARCMIN, 2 * coning.THETA_TOL
    slices = [_Crossed(K1, c), _Analytic(K2, b)]
    for s in slices:
        for f in coning.SAMPLE_FRACTIONS:
            s.solve(f * T)
            s.solve(-f * T)
    mixed = np.array(slices[0].twist)[np.argsort(slices[0].torque)]
    assert np.diff(mixed).min() < -coning.THETA_TOL    # both sides in one relation: not monotone
    theta, _ = coupled_twist(slices, T)
    th1 = 2 * T / K1 - c
    expect = th1 if th1 <= b else (2 * T - K1 * c + K2 * b) / (K1 + K2)
    assert theta == pytest.approx(expect, abs=coning.THETA_TOL)
    theta_m, _ = coupled_twist(slices, -T)
    assert theta_m == pytest.approx(-expect, abs=coning.THETA_TOL)
