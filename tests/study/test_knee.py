"""The hinge fit of lost motion against clearance, and the least-squares offset slopes."""

import numpy as np
import pandas as pd
import pytest

from hdwf.study.knee import clearance_um, fit_hinge, offset_slopes
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
