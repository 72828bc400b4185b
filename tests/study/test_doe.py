"""Designs of experiments: stratification, seeding, space filling."""

import numpy as np
import pytest

from hdwf import PARAMETER_COLUMNS, PARAMETERS
from hdwf.study.doe import optimal_lhs, space_filling, unit_sample

BOUNDS = {"d": (31.0, 31.016), "D": (41.984, 42.0), "Gr": (0.005, 0.02), "rFS": (0.0, 0.02), "rCS": (0.0, 0.02)}


def _strata(values, lo, hi, n):
    return np.floor((values - lo) / (hi - lo) * n).astype(int)


@pytest.mark.parametrize("optimization", ["random-cd", "none"])
def test_lhs_has_one_point_per_stratum(optimization):
    df, _ = optimal_lhs(BOUNDS, n=27, seed=3, optimization=optimization)
    assert len(df) == 27 and df["design_id"].is_unique
    for p, col in zip(PARAMETERS, PARAMETER_COLUMNS):
        lo, hi = BOUNDS[p]
        cells = _strata(df[col].to_numpy(), lo, hi, 27)
        assert sorted(cells) == list(range(27)), p  # Latin property: each of 27 slices exactly once


def test_seeded_and_optimised():
    a, crit_a = optimal_lhs(BOUNDS, n=27, seed=11)
    b, _ = optimal_lhs(BOUNDS, n=27, seed=11)
    assert a.equals(b)
    _, plain = optimal_lhs(BOUNDS, n=27, seed=11, optimization="none")
    # The optimisation exists to lower the discrepancy; scipy's random-cd never accepts a worse swap.
    assert crit_a.centered_l2_discrepancy < plain.centered_l2_discrepancy


def test_space_filling_of_a_known_design():
    # Two points at opposite corners of the unit square: distance sqrt(2), correlation 1.
    sf = space_filling(np.array([[0.0, 0.0], [1.0, 1.0]]))
    assert sf.maximin_distance == pytest.approx(np.sqrt(2))
    assert sf.max_abs_correlation == pytest.approx(1.0)


@pytest.mark.parametrize("sampler", ["lhs", "halton", "sobol"])
def test_samplers_are_uniform_and_seeded(sampler):
    x = unit_sample(sampler, 4096, 10, seed=5)
    assert x.shape == (4096, 10) and x.min() >= 0 and x.max() < 1
    # Each coordinate of a uniform sample has mean 1/2 and variance 1/12.
    assert np.allclose(x.mean(axis=0), 0.5, atol=0.01)
    assert np.allclose(x.var(axis=0), 1 / 12, atol=0.003)
    assert np.array_equal(x, unit_sample(sampler, 4096, 10, seed=5))


def test_sobol_needs_power_of_two():
    with pytest.raises(ValueError, match="power of two"):
        unit_sample("sobol", 100, 3, seed=0)


def test_synth_designs_sample_a_batch_inside_its_range():
    """`--range` narrows the Latin hypercube of a synthetic campaign: one specimen in each of
    the n equal strata of the narrowed range (the LHS property), the other parameters on the
    paper's Table 3 ranges as before, the same seed giving the same specimens."""
    from hdwf.validation.synthesis import synth_designs

    n = 8
    batch = synth_designs("hd42", n, 3, {"rFS_mm": (0.0, 0.002), "rCS_mm": (0.001, 0.001)})
    strata = np.floor(batch["rFS_mm"].to_numpy() / 0.002 * n).astype(int)
    assert sorted(strata) == list(range(n))
    assert (batch["rCS_mm"] == 0.001).all()                       # a zero-width range fixes it
    full = synth_designs("hd42", n, 3)
    np.testing.assert_array_equal(batch["d_mm"], full["d_mm"])    # same hypercube, other columns unchanged
    np.testing.assert_allclose(full["rFS_mm"] / 0.02, batch["rFS_mm"] / 0.002, rtol=1e-12)
