"""The hinge fit of lost motion against clearance, and the least-squares offset slopes."""

import numpy as np
import pandas as pd
import pytest

from hdwf.study.knee import MIN_FLOOR_DESIGNS, clearance_um, fit_hinge, floor_ranks, offset_slopes
from hdwf.study.paper import load_bounds, load_fea_designs

COLUMNS = ["d_mm", "D_mm", "Gr_mm", "rFS_mm", "rCS_mm"]


def _nominal(paper_dir, unit):
    return load_bounds(paper_dir, unit).loc["nominal"]


def test_an_exact_hinge_is_recovered(paper_dir):
    """Φ made from a known hinge over HD 42's Table 3 space comes back to round-off."""
    rng = np.random.default_rng(3)
    bounds = load_bounds(paper_dir, "hd42")
    designs = pd.DataFrame({c: rng.uniform(bounds.loc["minimal", c], bounds.loc["maximal", c], 60) for c in COLUMNS})
    nominal = bounds.loc["nominal"]
    s = clearance_um(designs, nominal, (1.5, -0.5, 0.8))
    designs["lost_motion_arcmin"] = 0.3 + 0.07 * np.maximum(0.0, s - 20.0)
    fit = fit_hinge(designs, nominal)
    assert (fit.floor_arcmin, fit.slope_arcmin_per_um, fit.knee_um) == pytest.approx((0.3, 0.07, 20.0), rel=1e-6)
    assert fit.weights == pytest.approx((1.5, -0.5, 0.8), rel=1e-5) and fit.r2 == pytest.approx(1.0)
    assert fit.predict(fit.clearance_um(designs, nominal)) == pytest.approx(designs["lost_motion_arcmin"])


@pytest.mark.parametrize("unit, floor, slope, knee, r2", [("hd42", 0.256, 0.0669, 24.6, 0.965),
                                                          ("hd120", 0.698, 0.0452, 78.7, 0.990)])
def test_the_papers_tables_give_the_published_knee(paper_dir, unit, floor, slope, knee, r2):
    """The paper's Tables 4/5 have a flat part and a knee (the fit ../shared/background.md quotes:
    about 0.15 m of offset absorbed, past it 0.2 to 0.38 of the rigid rate 2/r_b)."""
    fit = fit_hinge(load_fea_designs(paper_dir, unit), _nominal(paper_dir, unit))
    assert fit.floor_arcmin == pytest.approx(floor, abs=5e-4)
    assert fit.slope_arcmin_per_um == pytest.approx(slope, abs=5e-5)
    assert fit.knee_um == pytest.approx(knee, abs=0.05)
    assert fit.r2 == pytest.approx(r2, abs=5e-4)


@pytest.mark.parametrize("unit, per_um", [("hd42", 0.028), ("hd120", 0.035)])
def test_the_papers_offset_slope(paper_dir, unit, per_um):
    """dΦ/dr_FS of a linear fit over the 27 designs: 0.028 / 0.035 arcmin/µm (issue 15's reference)."""
    d_fs, d_cs = offset_slopes(load_fea_designs(paper_dir, unit))
    assert d_fs == pytest.approx(per_um, abs=5e-4) and d_cs == pytest.approx(d_fs, rel=0.05)


def test_a_rigid_backlash_has_no_flat_part(paper_dir):
    """Φ = 2 s / r_b with nothing absorbed (our bare section's law): the knee lies at or below the
    smallest clearance, the slope is the rigid rate and the floor what that gives there."""
    designs = load_fea_designs(paper_dir, "hd42")
    nominal = _nominal(paper_dir, "hd42")
    rate = 0.342   # arcmin per µm of r_FS + r_CS for HD 42 (2 / r_b)
    s = clearance_um(designs, nominal, (0.4, 0.0, 0.4))
    designs = designs.assign(lost_motion_arcmin=rate * s)
    fit = fit_hinge(designs, nominal)
    assert fit.slope_arcmin_per_um == pytest.approx(rate, rel=1e-6)
    assert fit.knee_um <= fit.clearance_um(designs, nominal).min() + 1e-6
    assert offset_slopes(designs)[0] == pytest.approx(rate, rel=1e-6)


def test_too_few_designs_are_refused(paper_dir):
    designs = load_fea_designs(paper_dir, "hd42").head(6)
    with pytest.raises(ValueError, match="at least 7 designs, got 6"):
        fit_hinge(designs, _nominal(paper_dir, "hd42"))


def _separated_hinge(paper_dir, trend, n=40, knee=26.0, gap=4.0, seed=5):
    """Designs over HD 42's Table 3 space whose clearance keeps ``gap`` µm clear of the knee, Φ a
    hinge plus a linear ``trend`` (arcmin per µm of each parameter) on the flat part only."""
    rng = np.random.default_rng(seed)
    bounds = load_bounds(paper_dir, "hd42")
    nominal = bounds.loc["nominal"]
    weights = (1.0, -1.0, 1.0)
    rows = []
    while len(rows) < n:
        design = {c: rng.uniform(bounds.loc["minimal", c], bounds.loc["maximal", c]) for c in COLUMNS}
        s = float(clearance_um(pd.DataFrame([design]), nominal, weights)[0])
        if abs(s - knee) > gap:
            rows.append(design)
    designs = pd.DataFrame(rows)
    s = clearance_um(designs, nominal, weights)
    change_um = 1e3 * (designs[COLUMNS] - nominal[COLUMNS]).to_numpy(float)
    flat = s < knee
    designs["lost_motion_arcmin"] = 0.3 + 0.07 * np.maximum(0.0, s - knee) + flat * (change_um @ np.asarray(trend))
    return designs, nominal, flat


def test_floor_ranks_recovers_a_trend_on_the_flat_part(paper_dir):
    """A linear trend put on the flat part only comes back exactly; a model equal to the
    reference ranks 1 everywhere."""
    trend = (0.001, -0.002, 0.0015, 0.0025, 0.002)
    designs, nominal, flat = _separated_hinge(paper_dir, trend)
    ranks = floor_ranks(designs, designs["lost_motion_arcmin"].to_numpy(), nominal)
    assert ranks.n_floor == flat.sum() >= MIN_FLOOR_DESIGNS
    assert ranks.floor_coefficients == pytest.approx(trend, abs=1e-9) and ranks.floor_r2 == pytest.approx(1.0)
    assert ranks.spearman_all == pytest.approx(1.0) and ranks.spearman_floor == pytest.approx(1.0)
    assert ranks.spearman_past == pytest.approx(1.0)


def test_the_rank_ceiling_of_a_flat_hinge_is_the_random_permutation_mean(paper_dir):
    """With the flat part's k designs in random order and the rest in the reference's order, Spearman's
    ρ = 1 − 6 Σd² / (n (n² − 1)) and a random permutation of k has E Σd² = k (k² − 1) / 6."""
    designs, nominal, flat = _separated_hinge(paper_dir, (0.001, -0.001, 0.001, 0.001, 0.001))
    ranks = floor_ranks(designs, designs["lost_motion_arcmin"].to_numpy(), nominal, draws=4000)
    n, k = len(designs), int(flat.sum())
    # sd of one draw about 0.03 here, so the mean of 4000 is good to about 0.0005
    assert ranks.spearman_ceiling == pytest.approx(1 - k * (k * k - 1) / (n * (n * n - 1)), abs=0.002)


def test_the_papers_flat_part_is_not_flat(paper_dir):
    """Table 4: 13 designs below the knee, whose Φ still rises with every clearance (R² 0.95), so
    its own hinge ranks the table at 0.910 and, with the flat part in random order, 0.86 on average."""
    reference = load_fea_designs(paper_dir, "hd42")
    nominal = _nominal(paper_dir, "hd42")
    ranks = floor_ranks(reference, reference["lost_motion_arcmin"].to_numpy(), nominal)
    assert ranks.n_floor == 13 and ranks.floor_r2 == pytest.approx(0.948, abs=5e-4) and ranks.floor_p < 1e-3
    assert np.sign(ranks.floor_coefficients).tolist() == [1, -1, 1, 1, 1]   # a looser fit, more play
    assert ranks.spearman_hinge == pytest.approx(0.9104, abs=5e-4)
    assert ranks.spearman_ceiling == pytest.approx(0.859, abs=0.01) and ranks.share_at_least < 0.2
    assert ranks.spearman_clearance == pytest.approx(0.938, abs=5e-4)   # Φ rising strictly with s would pass
    hd120 = floor_ranks(load_fea_designs(paper_dir, "hd120"), load_fea_designs(paper_dir, "hd120")["lost_motion_arcmin"]
                        .to_numpy(), _nominal(paper_dir, "hd120"))
    assert hd120.n_floor == 7 and np.isnan(hd120.floor_r2)   # too few for a fit in five parameters
    assert hd120.spearman_clearance == pytest.approx(0.964, abs=5e-4)


def test_floor_ranks_names_a_length_mismatch(paper_dir):
    reference = load_fea_designs(paper_dir, "hd42")
    with pytest.raises(ValueError, match="26 values for 27"):
        floor_ranks(reference, np.ones(26), _nominal(paper_dir, "hd42"))
