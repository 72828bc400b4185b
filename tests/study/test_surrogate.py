"""The quadratic surrogate of Eq. 11."""

import numpy as np
import pytest

from hdwf import PARAMETER_COLUMNS
from hdwf.study.paper import load_fea_designs
from hdwf.study.surrogate import design_matrix, fit_quadratic, rebound, term_names

LO, HI = np.array([0, 10, -1, 0, 5.0]), np.array([1, 20, 1, 2, 6.0])


def test_21_terms():
    assert len(term_names()) == 21


def test_a_quadratic_is_recovered_exactly():
    rng = np.random.default_rng(2)
    true = rng.normal(size=21)
    X = LO + rng.uniform(size=(40, 5)) * (HI - LO)
    u = 2 * (X - LO) / (HI - LO) - 1
    y = design_matrix(u) @ true
    model = fit_quadratic(X, y, LO, HI)
    assert model.coefficients == pytest.approx(true, abs=1e-9)
    assert model.r2 == pytest.approx(1.0) and model.q2_loo == pytest.approx(1.0) and model.rmse < 1e-10


def test_predictions_are_the_design_matrix_product():
    """The surrogate is evaluated as a quadratic form; it must be Eq. 11's product term by term."""
    rng = np.random.default_rng(5)
    X = LO + rng.uniform(size=(30, 5)) * (HI - LO)
    model = fit_quadratic(X, rng.normal(size=30), LO, HI)
    Z = LO + rng.uniform(size=(200, 5)) * (HI - LO)
    u = 2 * (Z - LO) / (HI - LO) - 1
    expected = design_matrix(u) @ np.asarray(model.coefficients)
    assert model.predict(Z) == pytest.approx(expected, abs=1e-12)
    assert model.predict_unit((u + 1) / 2) == pytest.approx(expected, abs=1e-12)


def test_q2_equals_brute_force_leave_one_out():
    rng = np.random.default_rng(3)
    X = LO + rng.uniform(size=(30, 5)) * (HI - LO)
    y = np.sin(X[:, 0] * 3) + X[:, 1] / 10 + rng.normal(scale=0.1, size=30)
    model = fit_quadratic(X, y, LO, HI)
    press = 0.0
    for i in range(len(y)):
        keep = np.arange(len(y)) != i
        press += (y[i] - fit_quadratic(X[keep], y[keep], LO, HI).predict(X[i:i + 1])[0]) ** 2
    assert model.q2_loo == pytest.approx(1 - press / np.sum((y - y.mean()) ** 2), rel=1e-9)


def test_rebound_keeps_the_function():
    rng = np.random.default_rng(4)
    X = LO + rng.uniform(size=(30, 5)) * (HI - LO)
    model = fit_quadratic(X, rng.normal(size=30), LO, HI)
    other = rebound(model, LO - 1, HI + 2, "wider")
    Z = LO + rng.uniform(size=(10, 5)) * (HI - LO)
    assert other.predict(Z) == pytest.approx(model.predict(Z), abs=1e-9)


@pytest.mark.parametrize("unit, r2_min", [("hd42", 0.98), ("hd120", 0.99)])
def test_paper_r2(paper_dir, unit, r2_min):
    df = load_fea_designs(paper_dir, unit)
    X = df[list(PARAMETER_COLUMNS)].to_numpy()
    model = fit_quadratic(X, df["lost_motion_arcmin"].to_numpy(), X.min(0), X.max(0))
    assert model.r2 >= r2_min  # the paper's Sect. 7.1
    assert model.q2_loo < model.r2  # out-of-sample skill is always below in-sample


def test_too_few_designs_is_an_error():
    with pytest.raises(ValueError, match="needs more than 21"):
        fit_quadratic(np.zeros((21, 5)), np.zeros(21), LO, HI)
