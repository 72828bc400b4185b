"""Lost motion against makers' catalogues: 2T/K1 of the compared units, ratios, refusals."""

import math

import numpy as np
import pytest

from hdwf.drive.geometry import unit_data
from hdwf.study.catalogue import CATALOGUE, catalogue_check, catalogue_units, size_ratio

ARCMIN = math.pi / (180 * 60)


def test_the_catalogue_holds_the_published_k1_and_t1():
    """Harmonic Drive CSF, ratio 50, K1 in 10^4 N m/rad below T1: the brief's background notes give
    sizes 17, 32 and 50 with their T1 in its catalogue section and size 45 beside the paper's fits."""
    published = {17: (0.81, 3.9), 32: (5.4, 29.0), 45: (15.0, 76.0), 50: (20.0, 108.0)}
    assert {u.size: (u.k1_Nm_per_rad / 1e4, u.t1_Nm) for u in CATALOGUE} == published
    assert [u.size for u in catalogue_units("hd42")] == [17] and [u.size for u in catalogue_units("hd120")] == [45, 50]


def test_a_catalogue_units_lost_motion_is_twice_the_test_torque_over_k1():
    """HD 42's ±0.96 N m (paper Table 1) on a size-17 unit: 2 * 0.96 / 8100 rad = 0.8148 arcmin; HD 120's
    ±21.16 N m between sizes 50 and 45: 2 * 21.16 / 2e5 and / 1.5e5 rad = 0.7274 and 0.9699 arcmin."""
    hd42 = catalogue_check("hd42", unit_data("hd42").torque_Nmm / 1000, {"ours": [0.3]})
    assert hd42.catalogue_phi_arcmin == pytest.approx((2 * 0.96 / 8100 / ARCMIN,) * 2, rel=1e-12)
    assert hd42.catalogue_phi_arcmin[0] == pytest.approx(0.8148, abs=1e-4)
    hd120 = catalogue_check("hd120", unit_data("hd120").torque_Nmm / 1000, {"ours": [0.3]})
    assert hd120.catalogue_phi_arcmin == pytest.approx((0.7274, 0.9699), abs=1e-4)


def test_a_model_as_stiff_as_the_catalogue_unit_has_ratio_one_and_its_k1():
    """Designs whose median Φ is 2T/K1 read as ratio 1 and a secant stiffness of K1; the median
    ignores a failed (NaN) design."""
    phi = 2 * 0.96 / 0.81e4 / ARCMIN
    check = catalogue_check("hd42", 0.96, {"ours": [phi * 0.5, phi, phi * 3, np.nan]})
    assert check.ratio("ours") == pytest.approx((1.0, 1.0), rel=1e-12)
    assert check.stiffness_Nm_per_rad("ours") == pytest.approx(0.81e4, rel=1e-12)


def test_the_catalogue_follows_the_size_law_and_a_model_is_held_against_it():
    """Torque and K1 both scale with the size cubed: HD 120's catalogue Φ over HD 42's spans 1
    (0.727/0.815 to 0.970/0.815); a model's ratio is its two medians'."""
    small = catalogue_check("hd42", 0.96, {"m": [0.25, 0.3, 0.35]})
    large = catalogue_check("hd120", 21.16, {"m": [0.6, 0.9]})
    lo, hi = size_ratio(small, large)
    assert lo < 1 < hi and (lo, hi) == pytest.approx((0.7274 / 0.8148, 0.9699 / 0.8148), abs=1e-3)
    assert size_ratio(small, large, "m") == pytest.approx((0.75 / 0.3,) * 2)


@pytest.mark.parametrize("unit, torque, values, said", [
    ("hd42", 3.9, {"m": [1.0]}, "not below T1 of size 17"),
    ("hd99", 1.0, {"m": [1.0]}, "no catalogue size compares with drive 'hd99'"),
    ("hd42", 0.96, {"m": [np.nan]}, "no finite lost motion in 'm'")])
def test_what_the_catalogue_cannot_judge_is_refused(unit, torque, values, said):
    with pytest.raises(ValueError, match=said):
        catalogue_check(unit, torque, values)


def test_a_drive_between_two_units_gives_its_ratio_low_end_against_the_softer_unit():
    """HD 120 between CSF-50 (2T/K1 0.727 arcmin) and CSF-45 (0.970): a median of 0.5 arcmin is
    0.5/0.970 = 0.515 of the softer unit's and 0.5/0.727 = 0.687 of the stiffer's, printed low first."""
    check = catalogue_check("hd120", 21.16, {"ours": [0.4, 0.5, 0.6]})
    assert check.ratio("ours") == pytest.approx((0.5 / 0.96990, 0.5 / 0.72743), rel=1e-4)
    assert check.stiffness_Nm_per_rad("ours") == pytest.approx(2 * 21.16 / (0.5 * ARCMIN), rel=1e-12)
