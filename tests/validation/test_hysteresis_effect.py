"""The micro-slip hysteresis candidate (``microslip_hysteresis``, issue 16 item 3): an Iwan
element in series at the output whose twist follows the test's torque sequence by the Masing
rule. Its parameter is the loop width w at zero torque in the drive's own lost-motion test, the
same for both drives; the element is the Iwan element of density a = 2 w / T^2, T the test
torque. Checked against its closed forms (docs/fe-model.md, "Micro-slip hysteresis"):

* first loading: theta = a T|T| / 2; after a reversal at (T_r, theta_r):
  theta = theta_r + a (T - T_r)|T - T_r| / 4 (the virgin curve scaled by 2 about the reversal);
* in the test 0 -> +T -> 0 -> -T -> 0 the branches are a T^2 / 2 = w apart at zero torque, and
  the lost motion grows by a T^2 = 2 w.

The FE checks solve one design per drive (HD 42 and HD 120) on the coarse campaign mesh (5 x 3
elements, half model) the way a campaign's specimen job does (``solve_specimen``): one contact
solve per drive shared by every value of the parameter, since the element is in series. Those
tests are marked slow.
"""

from __future__ import annotations

import numpy as np
import pytest

from hdwf.cli import main
from hdwf.drive.design import geometry_of, mesh_design
from hdwf.drive.geometry import ARCMIN
from hdwf.fe import (
    ModelChanges,
    series_output_twist,
    solve_lost_motion_variants,
    torque_fractions,
)
from hdwf.fe.series import microslip_twist
from hdwf.validation.effects import get, model_changes
from hdwf.validation.variants import SolveSetup, solve_specimen, variant_key

NAME, PARAM = "microslip_hysteresis", "loop_arcmin"
SETTINGS = {"elements_over_height": 5, "elements_over_thickness": 3, "refinement": 1.0, "symmetry": "half"}
SPECIMENS = {
    "hd42": {"specimen_id": "hd42-probe", "d_mm": 31.0, "D_mm": 42.0, "Gr_mm": 0.015,
             "rFS_mm": 0.005, "rCS_mm": 0.005},
    "hd120": {"specimen_id": "hd120-probe", "d_mm": 90.0, "D_mm": 120.0, "Gr_mm": 0.030,
              "rFS_mm": 0.005, "rCS_mm": 0.005},
}
TEST_TORQUE_NMM = {"hd42": 960.0, "hd120": 21160.0}   # 4 % of T_N (paper Table 1)
STEPS = 5
URAD_PER_NM2 = 1.0e-6 / 1.0e6    # 1 µrad/(N m)^2 in rad/(N mm)^2


def _masing_test_path(a: float, T: float, n: int) -> np.ndarray:
    """The element's twist along 0 -> +T -> 0 -> -T -> 0, written out branch by branch."""
    fr = torque_fractions(n)
    x = fr * T
    out = np.empty(x.size)
    up = a * x[: n + 1] ** 2 / 2                              # virgin curve
    top = a * T ** 2 / 2
    down = top + a * (x[n:3 * n + 1] - T) * np.abs(x[n:3 * n + 1] - T) / 4   # from (+T, top)
    back = -top + a * (x[3 * n:] + T) * np.abs(x[3 * n:] + T) / 4           # from (-T, -top)
    out[: n + 1], out[n:3 * n + 1], out[3 * n:] = up, down, back
    return out


def _series_loop(unit: str, loop_arcmin: float, n: int = STEPS) -> np.ndarray:
    """The element's twist (arcmin) along the drive's test path, as the tables add it."""
    frac = torque_fractions(n)
    return series_output_twist(np.zeros(frac.size), frac * TEST_TORQUE_NMM[unit],
                               model_changes({NAME: {PARAM: loop_arcmin}})) / ARCMIN


def test_the_test_torques_are_the_drives():
    for unit, spec in SPECIMENS.items():
        assert geometry_of(unit, spec).torque == TEST_TORQUE_NMM[unit]


@pytest.mark.parametrize("n", [5, 100])
def test_element_follows_the_masing_branches_on_the_test_path(n):
    a, T = 126.0 * URAD_PER_NM2, 960.0          # about HD 42 at 0.2 arcmin, N mm
    np.testing.assert_allclose(microslip_twist(torque_fractions(n) * T, a), _masing_test_path(a, T, n),
                               rtol=1e-12, atol=1e-18)


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
@pytest.mark.parametrize("n", [5, 100])
def test_loop_parameter_is_the_iwan_element_of_density_2w_over_T2(unit, n):
    """The series element at loop w is microslip_twist with a = 2 w / T^2 on the test path."""
    w = 0.2 * ARCMIN
    T = TEST_TORQUE_NMM[unit]
    np.testing.assert_allclose(_series_loop(unit, 0.2, n) * ARCMIN,
                               _masing_test_path(2 * w / T ** 2, T, n), rtol=1e-12, atol=1e-18)


def test_loop_width_by_hand():
    """w = 0.2 arcmin = 5.8178e-5 rad. HD 42 (T = 0.96 N m): a = 2 w / T^2 = 1.16355e-4 / 0.9216 =
    1.2625e-4 rad/(N m)^2 = 126.25 µrad/(N m)^2; HD 120 (T = 21.16 N m): 1.16355e-4 / 447.75 =
    0.25987 µrad/(N m)^2. Either way the branches at zero torque are 0.2 arcmin apart and the
    lost motion grows by 0.4 arcmin."""
    n = STEPS
    for unit, a_urad in (("hd42", 126.2536), ("hd120", 0.259869)):
        T = TEST_TORQUE_NMM[unit]
        tw = _series_loop(unit, 0.2)
        assert tw[2 * n] - tw[4 * n] == pytest.approx(0.2, abs=1e-12)
        assert tw[n] - tw[3 * n] == pytest.approx(0.4, abs=1e-12)
        by_hand = microslip_twist(torque_fractions(n) * T, a_urad * URAD_PER_NM2) / ARCMIN
        np.testing.assert_allclose(by_hand, tw, rtol=1e-6, atol=0)


def test_the_density_comes_from_the_paths_own_peak_torque():
    """a = 2 w / max|T|^2 on any path: the same w on a test to half the torque is the same loop,
    and a path without torque adds nothing."""
    frac = torque_fractions(STEPS)
    ch = model_changes({NAME: {PARAM: 0.5}})
    for T in (480.0, 960.0, 21160.0):
        tw = series_output_twist(np.zeros(frac.size), frac * T, ch) / ARCMIN
        assert tw[2 * STEPS] - tw[4 * STEPS] == pytest.approx(0.5, abs=1e-12)
    zero = series_output_twist(np.zeros(frac.size), np.zeros(frac.size), ch)
    assert np.array_equal(zero, np.zeros(frac.size))


def test_element_is_a_chain_of_sliders_with_memory():
    """Independent of the closed form: 4000 springs, each bridged by a Coulomb slider (slip
    torques evenly spread, midpoint rule), stepped one by one along a path with an inner loop.
    Masing/Madelung: the inner loop 800 -> 200 -> 500 -> 200 closes on itself; the way on from
    200 follows the branch that started at 800 as if the inner loop never was, reaches the
    mirror point (-800, -theta(800)) and beyond it goes on along the virgin curve."""
    a = 1.0e-9
    path = np.concatenate([np.linspace(0, 800, 9), np.linspace(700, 200, 6), np.linspace(300, 500, 3),
                           np.linspace(400, 200, 3), np.linspace(100, -900, 11), np.linspace(-800, 300, 12)])
    ds = 900.0 / 4000
    s = (np.arange(4000) + 0.5) * ds
    p, chain = np.zeros(s.size), []
    for T in path:
        p = np.clip(p, T - s, T + s)     # each slider holds its spring until it slips
        chain.append(a * ds * p.sum())
    got = microslip_twist(path, a)
    np.testing.assert_allclose(got, chain, rtol=0, atol=1e-6 * np.abs(got).max())
    first, second = np.flatnonzero(path == 200)[1:3]    # (the first 200 is on the virgin curve)
    assert got[second] == pytest.approx(got[first], rel=1e-12)      # inner loop closed
    top = a * 800 ** 2 / 2
    down = np.flatnonzero(np.diff(path, prepend=0.0) < 0)                # steps on a way down
    at = {T: got[down[path[down] == T][-1]] for T in (0.0, -800.0, -900.0)}
    assert at[0.0] == pytest.approx(top - a * 800 ** 2 / 4, rel=1e-12)   # the branch from 800
    assert at[-800.0] == pytest.approx(-top, rel=1e-12)                  # ... reaches the mirror point
    assert at[-900.0] == pytest.approx(-a * 900 ** 2 / 2, rel=1e-12)     # and goes on on the virgin curve


def test_effect_is_registered_and_listed(capsys):
    eff = get(NAME)
    assert eff.series and eff.off == {PARAM: 0.0}
    p = eff.param(PARAM)
    assert (p.lower, p.upper, p.realistic, p.transform, p.realistic_by_unit) == (0.0, 1.5, 0.2, "linear", ())
    assert p.realistic_for("hd42") == p.realistic_for("hd120") == 0.2
    assert main(["effects"]) == 0
    out = capsys.readouterr().out
    assert f"{NAME}: Micro-slip friction in the torque path (Masing/Iwan element) (in series at the output)" in out
    assert f"{PARAM} [arcmin] in [0, 1.5], realistic 0.2: " in out


def test_it_needs_no_contact_solve():
    """In series: its changes vanish from the part of the model the contact solver sees, so
    every value of its grid reuses the campaign model's solve."""
    ch = model_changes({NAME: {PARAM: 0.5}})
    assert ch.output_microslip_loop_rad == 0.5 * ARCMIN
    assert ch.fe_part() == ModelChanges()
    assert model_changes({NAME: {PARAM: 0.0}}) == ModelChanges()


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_loop_width_is_the_parameter_over_the_bounds_for_both_drives(unit):
    """At the lower bound, the realistic value and every grid value the loop at zero torque is
    the parameter itself (the lost motion grows by twice that): monotone over the grid, 0 to
    1.5 arcmin for either drive, so it spans 0.05-1 arcmin."""
    p = get(NAME).param(PARAM)
    values = sorted({p.lower, p.realistic_for(unit), *p.grid()})
    n = STEPS
    widths = []
    for v in values:
        tw = _series_loop(unit, v)
        assert tw[2 * n] - tw[4 * n] == pytest.approx(v, abs=1e-12)
        assert tw[n] - tw[3 * n] == pytest.approx(2 * v, abs=1e-12)
        widths.append(tw[2 * n] - tw[4 * n])
    assert widths[0] == 0.0 and values[-1] == p.upper
    assert np.all(np.diff(widths) > 0), widths
    assert widths[0] <= 0.05 and widths[-1] >= 1.0, widths


@pytest.fixture(scope="module", params=["hd42", "hd120"])
def table(request):
    """The specimen job's table for one drive's probe: the campaign model, the effect off, at
    its lower bound, realistic value and every grid value, and with the cup spring as well
    (one contact solve)."""
    unit = request.param
    p = get(NAME).param(PARAM)
    k_cup = get("fs_cup_torsion").param("K_Nm_per_rad").realistic_for(unit)
    values = sorted({p.lower, p.realistic_for(unit), *p.grid(), p.upper})
    variants = [{}] + [{NAME: {PARAM: v}} for v in values] + [
        {NAME: {PARAM: p.realistic_for(unit)}, "fs_cup_torsion": {"K_Nm_per_rad": k_cup}}]
    tab = solve_specimen(SolveSetup(unit, SETTINGS, STEPS), SPECIMENS[unit], variants).to_pandas()
    curves = {variant_key(v): tab[tab["variant"] == variant_key(v)] for v in variants}
    return unit, values, k_cup, curves


def _twist(curves, effects):
    return curves[variant_key(effects)]["twist_arcmin"].to_numpy()


@pytest.mark.slow
def test_grid_solves_never_fail_inside_the_bounds(table):
    """Every grid value, the bounds included, gives the whole test 0 -> +T -> 0 -> -T -> 0
    (4 x STEPS + 1 points, as far to -T as to +T), solved."""
    _, values, _, curves = table
    assert len(curves) == len(values) + 2        # the campaign model, each value, with the cup spring
    for key, c in curves.items():
        assert (c["status"] == "ok").all(), (key, c["status"].unique())
        assert c["step"].tolist() == list(range(4 * STEPS + 1)), key
        assert c["torque_Nm"].max() == pytest.approx(-c["torque_Nm"].min()) and c["torque_Nm"].max() > 0
        assert np.isfinite(c["twist_arcmin"]).all()


@pytest.mark.slow
def test_off_is_the_baseline_exactly(table):
    *_, curves = table
    assert np.array_equal(_twist(curves, {NAME: {PARAM: 0.0}}), _twist(curves, {}))


@pytest.mark.slow
def test_loop_width_on_the_solved_curve_is_the_parameter(table):
    """(curve with the effect - campaign model) at the zero-torque steps after +T and after -T:
    the parameter itself, to round-off; the lost motion grows by twice that. Monotone over the
    grid, and it spans 0.05-1 arcmin inside the bounds (0 at the lower bound, 1.5 at the upper),
    for either drive."""
    _, values, _, curves = table
    base = _twist(curves, {})
    n = STEPS
    widths = []
    for v in values:
        d = _twist(curves, {NAME: {PARAM: v}}) - base
        assert d[2 * n] - d[4 * n] == pytest.approx(v, abs=1e-9)
        assert d[n] - d[3 * n] == pytest.approx(2 * v, abs=1e-9)
        widths.append(d[2 * n] - d[4 * n])
    assert np.all(np.diff(widths) > 0), widths
    assert widths[0] <= 0.05 and widths[-1] >= 1.0, widths


@pytest.mark.slow
def test_it_adds_in_series_with_the_cup_spring(table):
    """Elements in series add: the lost motion is the campaign model's + 2 T/K (the cup) +
    2 w (the micro-slip element), to round-off."""
    unit, _, k_cup, curves = table
    w = get(NAME).param(PARAM).realistic_for(unit)
    base = _twist(curves, {})
    both = _twist(curves, {NAME: {PARAM: w}, "fs_cup_torsion": {"K_Nm_per_rad": k_cup}})
    n, T = STEPS, geometry_of(unit, SPECIMENS[unit]).torque
    extra = 2 * T / (k_cup * 1000.0) / ARCMIN + 2 * w
    assert (both[n] - both[3 * n]) - (base[n] - base[3 * n]) == pytest.approx(extra, abs=1e-9)


@pytest.mark.slow
def test_the_single_solve_applies_it_as_the_table_does(table):
    """``solve_lost_motion_variants`` (the single-design path, series_output_twist on the rim
    twist) gives the table's curve for the realistic value."""
    unit, _, _, curves = table
    w = get(NAME).param(PARAM).realistic_for(unit)
    ch = model_changes({NAME: {PARAM: w}})
    spec = SPECIMENS[unit]
    res = solve_lost_motion_variants(geometry_of(unit, spec), mesh_design(unit, spec, SETTINGS), STEPS, [ch])[0]
    assert res.status == "ok", res.reason
    np.testing.assert_allclose(res.twist_arcmin, _twist(curves, {NAME: {PARAM: w}}), rtol=0, atol=1e-9)
