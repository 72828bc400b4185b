"""Agreement of ours with the paper's Φ, and its band under mesh scatter: against cases with known answers."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from hdwf.study.agreement import agreement, agreement_under_mesh_scatter
from hdwf.study.knee import offset_slope_weights

PAPER = np.array([0.34, 0.19, 0.33, 1.09, 0.25, 0.51, 0.71, 1.49, 0.22, 0.40, 0.95, 0.28])


def test_agreement_is_scipys_spearman_and_pearson_squared_and_the_median_ratio():
    ours = PAPER * np.linspace(0.8, 1.3, PAPER.size) + 0.02 * np.sin(np.arange(PAPER.size))
    a = agreement(PAPER, ours)
    assert a.n == PAPER.size
    assert a.spearman == pytest.approx(stats.spearmanr(PAPER, ours).statistic, abs=1e-12)
    assert a.r2 == pytest.approx(stats.pearsonr(PAPER, ours).statistic ** 2, abs=1e-12)
    assert a.median_ratio == pytest.approx(np.median(ours / PAPER), abs=1e-12)


def test_a_proportional_model_agrees_exactly_in_rank_and_shape():
    a = agreement(PAPER, 2.5 * PAPER)
    assert (a.median_ratio, a.spearman, a.r2) == pytest.approx((2.5, 1.0, 1.0), abs=1e-12)


def test_designs_missing_either_value_are_left_out():
    ours = 2.0 * PAPER
    ours[3] = np.nan
    a = agreement(PAPER, ours)
    assert a.n == PAPER.size - 1 and a.spearman == pytest.approx(1.0)


def test_no_mesh_change_collapses_the_band_onto_the_figures():
    ours = PAPER * np.linspace(0.7, 1.4, PAPER.size)
    a, b = agreement(PAPER, ours), agreement_under_mesh_scatter(PAPER, ours, [0.0, 0.0])
    for (lo, hi), point in ((b.median_ratio, a.median_ratio), (b.spearman, a.spearman), (b.r2, a.r2)):
        assert lo == pytest.approx(point, abs=1e-12) and hi == pytest.approx(point, abs=1e-12)


def test_changes_too_small_to_reorder_leave_the_rank_at_one():
    # sorted neighbours differ by >= 10 %, so a change of at most 4 % each cannot swap two ranks
    paper = 0.2 * 1.1 ** np.arange(15)
    b = agreement_under_mesh_scatter(paper, 3.0 * paper, [0.04, 0.01, 0.03])
    assert b.spearman == (1.0, 1.0)
    assert 3.0 * 0.96 <= b.median_ratio[0] < b.median_ratio[1] <= 3.0 * 1.04
    assert b.r2[1] <= 1.0 and b.r2[0] > 0.99


def test_rank_and_shape_bands_do_not_depend_on_our_scale_and_the_ratio_band_scales():
    ours = PAPER * np.linspace(0.7, 1.4, PAPER.size)
    changes = [0.01, 0.02, 0.05, 0.15]
    b1 = agreement_under_mesh_scatter(PAPER, ours, changes, seed=7)
    b2 = agreement_under_mesh_scatter(PAPER, 4.0 * ours, changes, seed=7)
    assert b2.spearman == pytest.approx(b1.spearman, abs=1e-12)
    assert b2.r2 == pytest.approx(b1.r2, abs=1e-12)
    assert b2.median_ratio == pytest.approx(tuple(4.0 * v for v in b1.median_ratio), rel=1e-12)


def test_larger_scatter_widens_the_band_and_the_same_seed_repeats_it():
    ours = PAPER * np.linspace(0.7, 1.4, PAPER.size)
    small = agreement_under_mesh_scatter(PAPER, ours, [0.01])
    large = agreement_under_mesh_scatter(PAPER, ours, [0.2])
    assert np.ptp(large.r2) > np.ptp(small.r2) and np.ptp(large.spearman) > np.ptp(small.spearman)
    assert agreement_under_mesh_scatter(PAPER, ours, [0.2]) == large


@pytest.mark.parametrize("paper, ours, changes, match", [
    (PAPER, PAPER[:-1], [0.01], "one length"),
    (PAPER[:2], PAPER[:2], [0.01], "at least 3"),
    (PAPER, PAPER, [np.nan], "no measured mesh change"),
])
def test_bad_input_is_refused_with_what_is_wrong(paper, ours, changes, match):
    with pytest.raises(ValueError, match=match):
        agreement_under_mesh_scatter(paper, ours, changes)


def _designs(n: int = 27, seed: int = 5) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    return pd.DataFrame({"d_mm": 31 + 0.016 * rng.random(n), "D_mm": 41.984 + 0.016 * rng.random(n),
                         "Gr_mm": 0.005 + 0.015 * rng.random(n), "rFS_mm": 0.02 * rng.random(n),
                         "rCS_mm": 0.02 * rng.random(n)})


def test_the_slope_band_is_the_least_squares_slope_ratio_and_scales_with_ours():
    """Φ linear in the parameters: w · Φ is its r_FS coefficient exactly; with no mesh change the band
    is that ratio, and ours × 3 triples it (the slope is linear in Φ)."""
    designs = _designs()
    w = offset_slope_weights(designs)["rFS_mm"]
    paper = 0.2 + 28.0 * designs.rFS_mm + 29.0 * designs.rCS_mm + 5.0 * designs.Gr_mm   # 0.028 arcmin/µm
    ours = 0.1 + 44.0 * designs.rFS_mm + 47.0 * designs.rCS_mm
    assert w @ paper.to_numpy() == pytest.approx(0.028, rel=1e-9)
    b = agreement_under_mesh_scatter(paper, ours, [0.0], slope_weights=w)
    assert b.slope_ratio == pytest.approx((44 / 28, 44 / 28), rel=1e-9)
    changes = [0.02, 0.05, 0.1]
    b1 = agreement_under_mesh_scatter(paper, ours, changes, slope_weights=w)
    b3 = agreement_under_mesh_scatter(paper, 3.0 * ours, changes, slope_weights=w)
    assert b3.slope_ratio == pytest.approx(tuple(3.0 * v for v in b1.slope_ratio), rel=1e-9)
    assert b1.slope_ratio[0] < 44 / 28 < b1.slope_ratio[1]


def test_slope_weights_of_another_length_are_refused():
    with pytest.raises(ValueError, match="one weight per design"):
        agreement_under_mesh_scatter(PAPER, PAPER, [0.01], slope_weights=np.ones(3))


def test_tied_values_rank_as_scipy_ranks_them():
    """Spearman of every draw is Pearson of average ranks, scipy's definition with ties."""
    ours = np.round(PAPER * np.linspace(0.7, 1.4, PAPER.size), 1)   # rounding makes ties
    assert len(np.unique(ours)) < ours.size
    b = agreement_under_mesh_scatter(PAPER, ours, [0.0])
    assert b.spearman == pytest.approx((stats.spearmanr(PAPER, ours).statistic,) * 2, abs=1e-12)


def test_the_share_of_draws_meeting_a_target_is_counted_from_the_draws():
    ours = PAPER * np.linspace(0.7, 1.4, PAPER.size)
    b = agreement_under_mesh_scatter(PAPER, ours, [0.05, 0.2], draws=500)
    assert b.share("r2", b.r2[0], b.r2[1]) == pytest.approx(0.9, abs=0.005)   # between the 5 and 95 % quantiles
    assert b.share("spearman", -1.0, 1.0) == 1.0 and b.share("median_ratio", 10.0) == 0.0
    with pytest.raises(KeyError, match="slope_ratio"):
        b.share("slope_ratio", 0.5, 2.0)   # no slope weights given


def test_a_mesh_change_of_100_percent_or_more_is_refused():
    with pytest.raises(ValueError, match="zero or negative"):
        agreement_under_mesh_scatter(PAPER, PAPER, [0.02, 1.0])
