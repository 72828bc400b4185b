"""The solver's linear algebra: the bodies' Cholesky factor, the KKT solve of an active set and
the column store's combination, each against a direct dense computation."""

import numpy as np
import pytest
import scipy.sparse as sp

from hdwf.fe.active_factor import ActiveFactor, solve_frictionless_kkt, solve_kkt
from hdwf.fe.bodies import factorize_spd, plane_stress_lame
from hdwf.fe.column_store import CHUNK_ROWS, ColumnStore

from tests.fe.test_active_factor import _WorkingSet


def _factor(n):
    return lambda C: ActiveFactor().solver(C, np.arange(n), np.diag(C), _WorkingSet())


def _laplacian_2d(n: int) -> sp.csr_matrix:
    """The 5-point Laplacian of an n x n grid with Dirichlet edges: SPD, sparse like a stiffness."""
    T = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    return (sp.kron(sp.eye(n), T) + sp.kron(T, sp.eye(n))).tocsr()


def test_cholesky_factor_solves_vectors_and_blocks_as_a_dense_solve():
    K = _laplacian_2d(20)
    rng = np.random.default_rng(3)
    F = rng.standard_normal((K.shape[0], 7))
    factor = factorize_spd(K)
    exact = np.linalg.solve(K.toarray(), F)
    assert np.allclose(factor.solve(F), exact, rtol=0, atol=1e-10 * np.abs(exact).max())
    # a single column, and a Fortran-ordered block (copied to the C order cholespy takes)
    assert np.allclose(factor.solve(F[:, 2]), exact[:, 2], rtol=0, atol=1e-10 * np.abs(exact).max())
    assert np.allclose(factor.solve(np.asfortranarray(F)), exact, rtol=0, atol=1e-10 * np.abs(exact).max())
    # no columns at all (an empty set of rows): an empty answer, not a crash of the library
    assert factor.solve(F[:, :0]).shape == (K.shape[0], 0)


def test_cholesky_factor_refuses_a_matrix_that_is_not_positive_definite():
    # a floating body with nothing pinned: its stiffness is singular (a rigid translation)
    K = sp.csr_matrix(np.array([[1.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]))
    with pytest.raises(ValueError, match="positive definite"):
        factorize_spd(K)


def test_cholesky_factor_of_a_plane_stress_bar_gives_its_analytic_stretch():
    # a chain of n springs k = E A / L_e in series, the far end pulled by P: u = P L / (E A)
    E, A, L, n, P = 210000.0, 2.0, 10.0, 40, 100.0
    k = E * A / (L / n)
    K = sp.diags([-k * np.ones(n - 1), np.r_[2 * k * np.ones(n - 1), k], -k * np.ones(n - 1)], [-1, 0, 1])
    f = np.zeros(n)
    f[-1] = P
    u = factorize_spd(K).solve(f)
    assert u[-1] == pytest.approx(P * L / (E * A), rel=1e-12)


def test_plane_stress_shear_modulus_is_e_over_two_one_plus_nu():
    E = 210000.0
    assert plane_stress_lame(E, 0.3)[1] == pytest.approx(E / 2.6)


@pytest.mark.parametrize("n_modes", [0, 1, 3])
def test_frictionless_kkt_by_schur_complement_equals_the_lu_solve(n_modes):
    rng = np.random.default_rng(n_modes)
    nA = 40
    B = rng.standard_normal((nA, nA))
    C = B @ B.T + nA * np.eye(nA)
    H = rng.standard_normal((nA, n_modes))
    M = np.block([[C, H], [H.T, -1e-14 * np.eye(n_modes)]])
    rhs = rng.standard_normal(nA + n_modes)
    assert np.allclose(solve_frictionless_kkt(M, rhs, nA, _factor(nA)), np.linalg.solve(M, rhs), rtol=0,
                       atol=1e-10)
    assert np.allclose(solve_kkt(M, rhs), np.linalg.solve(M, rhs), rtol=0, atol=1e-10)


def test_kkt_with_a_c_that_is_not_positive_definite_falls_back_to_lu():
    C = np.diag([2.0, -1.0, 3.0])          # indefinite: Cholesky fails, LU does not
    M = np.block([[C, np.ones((3, 1))], [np.ones((1, 3)), np.zeros((1, 1))]])
    rhs = np.array([1.0, 2.0, 3.0, 0.5])
    assert np.allclose(solve_frictionless_kkt(M, rhs, 3, _factor(3)), np.linalg.solve(M, rhs), atol=1e-12)


@pytest.mark.parametrize("active", [3, 50])   # a few columns (gathered) and most of them (one pass)
def test_column_store_combination_is_the_weighted_sum_of_its_columns(active):
    rng = np.random.default_rng(active)
    X = rng.standard_normal((30, 60))
    store = ColumnStore(30)
    store.append(X[:, :25])
    store.append(X[:, 25:])
    positions = np.sort(rng.choice(60, size=active, replace=False))
    weights = rng.standard_normal(active)
    assert np.allclose(store.combine(positions, weights), X[:, positions] @ weights, rtol=0, atol=1e-12)


def test_column_store_copies_are_independent_across_chunks():
    """A copy shares its original's chunks until one side writes: renewing or adding columns on
    either side never shows on the other (stores of more than one chunk, appends that straddle
    a chunk boundary)."""
    rng = np.random.default_rng(7)
    n = CHUNK_ROWS + 40
    X = rng.standard_normal((12, n))
    store = ColumnStore(12)
    store.append(X[:, :CHUNK_ROWS - 5])
    store.append(X[:, CHUNK_ROWS - 5:])            # straddles the first chunk's end
    twin = store.copy()
    renewed = rng.standard_normal((12, 2))
    twin.replace(np.array([3, CHUNK_ROWS + 1]), renewed)
    extra = rng.standard_normal((12, 3))
    store.append(extra)
    assert np.array_equal(store.columns, np.hstack([X, extra]))
    expected = X.copy()
    expected[:, [3, CHUNK_ROWS + 1]] = renewed
    assert np.array_equal(twin.columns, expected)
    assert twin.size == n and store.size == n + 3


def test_column_store_projection_and_products_match_dense_algebra():
    """``project`` from a start inside a chunk, ``right_multiply`` and the one-pass ``combine``
    equal the dense products of the stacked columns."""
    rng = np.random.default_rng(11)
    n = 2 * CHUNK_ROWS + 17
    X = rng.standard_normal((20, n))
    store = ColumnStore(20)
    store.append(X)
    G = sp.random(6, 20, density=0.3, random_state=3, format="csr")
    start, stop = CHUNK_ROWS - 9, 2 * CHUNK_ROWS + 4
    assert np.allclose(store.project(G, stop, start), G @ X[:, start:stop], rtol=0, atol=1e-12)
    C = sp.random(n, 4, density=0.05, random_state=5, format="csc")
    assert np.allclose(store.right_multiply(C), X @ C.toarray(), rtol=0, atol=1e-12)
    w = rng.standard_normal(n)
    assert np.allclose(store.combine(np.arange(n), w), X @ w, rtol=0, atol=1e-11)
