"""The kept factor of the active block solves every block as a direct solve does."""

import numpy as np
import pytest

from hdwf.fe.active_factor import ActiveFactor

N_SET = 120         # pairs of the working set
REG = 1e-13


class _WorkingSet:
    """What the factor reads of a working set: its identity and its generation."""
    generation = 0


def _compliance(rng):
    A = rng.standard_normal((N_SET, N_SET))
    return A @ A.T / N_SET + 0.1 * np.eye(N_SET)


def _block(compliance, positions, s):
    """The block without and with the solver's regularisation."""
    C = compliance[np.ix_(positions, positions)].copy()
    C[np.diag_indices_from(C)] += s[positions]
    return C, C + REG * np.eye(positions.size)


def _check(factor, compliance, positions, s, ws, rng):
    bare, C = _block(compliance, positions, s)
    B = rng.standard_normal((positions.size, 3))
    X = factor.solver(C, positions, np.diag(bare), ws)(B)
    np.testing.assert_allclose(X, np.linalg.solve(C, B), rtol=0, atol=1e-10 * np.abs(X).max())


def test_a_layer_iteration_reuses_the_stable_factor_and_solves_as_a_direct_solve():
    """The solver's pattern: a block, then the same pairs with the diagonal moved on a third of
    them (the layer's edge pairs), then pairs added and volatile ones dropped.  Every solve equals
    np.linalg.solve to 1e-10; only the first block of a generation, the one after it (that learns
    which pairs move) and the one whose stable pair left are factorised whole."""
    rng = np.random.default_rng(3)
    compliance = _compliance(rng)
    s = rng.uniform(0.1, 1.0, N_SET)
    ws, factor = _WorkingSet(), ActiveFactor(min_pairs=0)
    positions = np.sort(rng.choice(N_SET, 80, replace=False))
    moving = positions[rng.choice(positions.size, 25, replace=False)]
    _check(factor, compliance, positions, s, ws, rng)         # new generation: all moved
    for _ in range(4):                                        # the layer's passes
        s[moving] *= rng.uniform(0.8, 1.2, moving.size)
        _check(factor, compliance, positions, s, ws, rng)
    assert (factor.factorisations, factor.updates) == (2, 3)
    added = np.setdiff1d(np.arange(N_SET), positions)[:5]
    positions = np.sort(np.concatenate([np.setdiff1d(positions, moving[:3]), added]))
    s[moving[3:]] *= 1.1
    _check(factor, compliance, positions, s, ws, rng)         # pairs in, volatile pairs out
    assert (factor.factorisations, factor.updates) == (2, 4)
    stable = np.setdiff1d(positions, np.concatenate([moving, added]))
    positions = np.setdiff1d(positions, stable[:1])
    _check(factor, compliance, positions, s, ws, rng)         # a stable pair left: factorised
    assert factor.factorisations == 3


def test_a_new_generation_or_another_working_set_is_factorised_anew():
    """Re-linearised rows change the off-diagonal part: nothing kept may be used."""
    rng = np.random.default_rng(5)
    compliance = _compliance(rng)
    s = rng.uniform(0.1, 1.0, N_SET)
    ws, factor = _WorkingSet(), ActiveFactor(min_pairs=0)
    positions = np.arange(0, N_SET, 2)
    _check(factor, compliance, positions, s, ws, rng)
    s[positions[:10]] *= 1.3
    _check(factor, compliance, positions, s, ws, rng)
    s[positions[:10]] *= 1.3
    _check(factor, compliance, positions, s, ws, rng)
    assert factor.updates == 1
    ws.generation += 1
    compliance = _compliance(rng)
    _check(factor, compliance, positions, s, ws, rng)
    other = _WorkingSet()
    _check(factor, compliance, positions, s, other, rng)
    assert factor.updates == 1


def test_a_small_block_is_factorised_directly_and_keeps_nothing():
    """Below ``MIN_KEPT_PAIRS`` a Cholesky costs less than the kept factor's bookkeeping."""
    rng = np.random.default_rng(9)
    compliance = _compliance(rng)
    s = rng.uniform(0.1, 1.0, N_SET)
    ws, factor = _WorkingSet(), ActiveFactor()
    assert factor.min_pairs > N_SET
    positions = np.arange(N_SET)
    for _ in range(3):
        s[:10] *= 1.2
        _check(factor, compliance, positions, s, ws, rng)
    assert (factor.factorisations, factor.updates) == (0, 0)


def test_a_block_that_is_not_positive_definite_raises():
    """The solver then falls back to an LU of the KKT matrix."""
    C = np.array([[1.0, 2.0], [2.0, 1.0]])
    with pytest.raises(np.linalg.LinAlgError):
        ActiveFactor().solver(C, np.array([0, 1]), np.diag(C), _WorkingSet())
    with pytest.raises(np.linalg.LinAlgError):
        ActiveFactor(min_pairs=0).solver(C, np.array([0, 1]), np.diag(C), _WorkingSet())
