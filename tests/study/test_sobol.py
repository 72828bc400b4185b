"""Sobol' indices: exact values of known decompositions, numerical integration, SALib estimates."""

import numpy as np
import pytest

from hdwf import PARAMETER_COLUMNS
from hdwf.study.paper import load_fea_designs, load_published
from hdwf.study.sobol import convergence, estimate_indices, exact_indices, exact_quadratic_indices, radial_matrix
from hdwf.study.surrogate import fit_quadratic


def test_additive_linear_function():
    # f = u1 + u2: equal variances, no interaction.
    s1, st = exact_quadratic_indices([1, 1], [0, 0], np.zeros((2, 2)))
    assert s1 == pytest.approx([0.5, 0.5]) and st == pytest.approx([0.5, 0.5])


def test_pure_interaction():
    # f = u1 u2: no main effect at all, every variance is interaction.
    s1, st = exact_quadratic_indices([0, 0], [0, 0], [[0, 1], [0, 0]])
    assert s1 == pytest.approx([0, 0]) and st == pytest.approx([1, 1])


def test_mixed_by_hand():
    # f = u1 + u2^2 + u1 u3: V1 = 1/3, V2 = 4/45, V13 = 1/9; V = 1/3 + 4/45 + 1/9 = 24/45.
    s1, st = exact_quadratic_indices([1, 0, 0], [0, 1, 0], [[0, 0, 1], [0, 0, 0], [0, 0, 0]])
    assert s1 == pytest.approx([15 / 24, 4 / 24, 0])
    assert st == pytest.approx([20 / 24, 4 / 24, 5 / 24])


def test_exact_agrees_with_gauss_legendre_integration():
    """S_i = Var(E[f | u_i]) / Var(f) computed on a tensor Gauss-Legendre grid (exact for quadratics)."""
    rng = np.random.default_rng(7)
    a, q, r = rng.normal(size=3), rng.normal(size=3), np.triu(rng.normal(size=(3, 3)), 1)
    nodes, weights = np.polynomial.legendre.leggauss(3)
    weights = weights / 2
    U = np.array(np.meshgrid(nodes, nodes, nodes, indexing="ij"))
    W = np.einsum("i,j,k->ijk", weights, weights, weights)
    f = sum(a[i] * U[i] + q[i] * U[i] ** 2 for i in range(3)) + sum(r[i, j] * U[i] * U[j] for i in range(3)
                                                                      for j in range(i + 1, 3))
    mean = np.sum(W * f)
    var = np.sum(W * (f - mean) ** 2)
    s1, _ = exact_quadratic_indices(a, q, r)
    for i in range(3):
        other = tuple(k for k in range(3) if k != i)
        cond = np.sum(W * f, axis=other) / np.sum(W, axis=other)  # E[f | u_i] at the nodes
        assert np.sum(weights * (cond - mean) ** 2) / var == pytest.approx(s1[i], rel=1e-10)


def test_radial_matrix_order():
    base = np.arange(2 * 4, dtype=float).reshape(2, 4)  # two points, k = 2
    m = radial_matrix(base)
    assert m.tolist() == [[0, 1], [2, 1], [0, 3], [2, 3], [4, 5], [6, 5], [4, 7], [6, 7]]


def _paper_model(paper_dir, unit):
    df = load_fea_designs(paper_dir, unit)
    X = df[list(PARAMETER_COLUMNS)].to_numpy()
    return fit_quadratic(X, df["lost_motion_arcmin"].to_numpy(), X.min(0), X.max(0), "design_range")


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_sobol_sequence_estimate_at_65536_matches_exact(paper_dir, unit):
    model = _paper_model(paper_dir, unit)
    exact = exact_indices(model).set_index("parameter")
    est = estimate_indices(model.predict_unit, model.parameters, "sobol", 65536, seed=4242 + 16,
                           num_resamples=20).set_index("parameter")
    for idx in ("S1", "ST"):
        assert np.abs(est[idx] - exact[idx]).max() < 0.005


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_paper_indices_reproduced(paper_dir, unit):
    exact = exact_indices(_paper_model(paper_dir, unit)).set_index("parameter")
    # rFS and rCS carry the two largest total effects, as the paper finds.
    assert set(exact["ST"].nlargest(2).index) == {"rFS", "rCS"}
    pub = load_published(paper_dir)
    # The paper's indices are sampling estimates over bounds it does not state; ours are exact over
    # the span of its designs. Every index agrees within 0.025 (HD 120's smallest published, 0.052 for
    # G_r, then within half its value), but HD 42's S_T of r_CS: the published 0.5513 lies 0.060 above
    # the exact 0.4913 (docs/results.md gives that gap as the replication's largest).
    for r in pub[(pub.unit == unit) & pub.statistic.str.startswith("sobol")].itertuples():
        diff = exact.loc[r.parameter, r.statistic.split("_")[1]] - r.value
        if (unit, r.parameter, r.statistic) == ("hd42", "rCS", "sobol_ST"):
            assert diff == pytest.approx(-0.060, abs=1e-3)
        else:
            assert abs(diff) < 0.025, (r.parameter, r.statistic, diff)


def test_convergence_stops_at_tolerance_and_reports_failure():
    f = lambda U: U[:, 0] + 2 * U[:, 1] + U[:, 0] * U[:, 2]  # noqa: E731
    table, status = convergence(f, ["a", "b", "c"], "sobol", n_start=64, n_min=256, n_max=8192,
                                tolerance=0.01, seed=1, num_resamples=20)
    assert status["converged"] and status["n_converged"] >= 256
    assert table["n"].max() == status["n_converged"]
    _, status = convergence(f, ["a", "b", "c"], "lhs", n_start=64, n_min=64, n_max=128, tolerance=1e-9,
                            seed=1, num_resamples=20)
    assert not status["converged"] and "not reached" in status["reason"]


def test_bootstrap_is_salibs_bootstrap():
    """The half-widths are SALib's: each chunk's resamples are the ones SALib draws with that
    chunk's seed (``keep_resamples``), to round-off, and the point estimates are SALib's; 100
    resamples in chunks agree with SALib's single call of 100 within the sampling error of a
    standard deviation from 100 resamples (about 7 % each; 35 % is over 3.5 sigma of the
    difference)."""
    from SALib.analyze import sobol as salib_sobol

    from hdwf.study import sobol
    from hdwf.study.doe import unit_sample

    f = lambda U: U[:, 0] + 2 * U[:, 1] + U[:, 0] * U[:, 2]  # noqa: E731
    names, n, seed = ["a", "b", "c"], 4096, 11
    y = f(radial_matrix(unit_sample("lhs", n, 6, seed)))
    problem = {"num_vars": 3, "names": names, "bounds": [[0.0, 1.0]] * 3}
    resampled = sobol._bootstrap(y, 3, n, 41, seed)
    for i, (start, size) in enumerate([(0, 20), (20, 21)]):
        ref = salib_sobol.analyze(problem, y, calc_second_order=False, num_resamples=size, seed=seed + 7919 * i,
                                  keep_resamples=True)
        for name in ("S1", "ST"):
            np.testing.assert_allclose(resampled[name][start:start + size], ref[f"{name}_conf_all"], rtol=1e-10)
    one = estimate_indices(f, names, "lhs", n, seed, num_resamples=sobol.BOOTSTRAP_CHUNK)
    ref = salib_sobol.analyze(problem, y, calc_second_order=False, num_resamples=sobol.BOOTSTRAP_CHUNK, seed=seed)
    for name in ("S1", "S1_conf", "ST", "ST_conf"):
        np.testing.assert_allclose(one[name], ref[name], rtol=1e-10)
    many = estimate_indices(f, names, "lhs", n, seed, num_resamples=100)
    ref = salib_sobol.analyze(problem, y, calc_second_order=False, num_resamples=100, seed=seed + 1)
    for name in ("S1", "ST"):
        np.testing.assert_allclose(many[f"{name}_conf"], ref[f"{name}_conf"], rtol=0.35)
    assert sobol._chunks(100) == [20] * 5 and sobol._chunks(41) == [20, 21] and sobol._chunks(2) == [2]
    with pytest.raises(ValueError, match="num_resamples"):
        sobol._chunks(1)
