"""The gaps of an active-set iterate from projected columns equal G applied to the displacement."""

from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp

from hdwf.fe.working_set import ProjectedColumns, WorkingSet

NWATCH, NROWS = 60, 25


class _Structure:
    """A stand-in with a dense SPD compliance: K^-1 G^T and its twist q^T K^-1 G^T."""

    def __init__(self, rng):
        A = rng.standard_normal((NWATCH, NWATCH))
        self.compliance = A @ A.T + NWATCH * np.eye(NWATCH)
        self.twist = rng.standard_normal(NWATCH)

    def compliance_columns(self, G):
        X = self.compliance @ G.toarray().T
        return X, self.twist @ X


def _rows(rng, nnz_per_row=3):
    """Sparse rows like contact rows: a handful of watch entries each."""
    r = np.repeat(np.arange(NROWS), nnz_per_row)
    c = rng.integers(0, NWATCH, r.size)
    return sp.csr_matrix((rng.standard_normal(r.size), (r, c)), shape=(NROWS, NWATCH))


def test_projected_columns_give_the_gaps_of_the_displacement_as_the_set_grows_and_is_refreshed():
    """Linearity: G (sum_k p_k x_k) = sum_k p_k (G x_k), whichever columns were projected when.
    Checked after the first pairs, after more enter (only the new columns are projected), and
    after a refresh renews some columns (a stale projection would keep the old numbers)."""
    rng = np.random.default_rng(7)
    structure = _Structure(rng)
    G = _rows(rng)
    rows = {"tooth": SimpleNamespace(G=G)}
    ws = WorkingSet(NWATCH)
    projected = ProjectedColumns(G)

    def check(positions):
        weights = rng.standard_normal(positions.size)
        direct = G @ ws.store.combine(positions, weights)
        np.testing.assert_allclose(projected.combine(ws, positions, weights), direct,
                                   rtol=1e-12, atol=1e-12 * np.abs(direct).max())

    ws.add(structure, rows, [("tooth", i) for i in range(6)])
    check(np.array([0, 2, 5]))
    ws.add(structure, rows, [("tooth", i) for i in range(6, 15)])
    check(np.array([1, 7, 9, 14]))
    assert projected.store.size == 15

    moved = rows["tooth"].G.tolil()
    moved[3, :] = 0.0
    moved[3, 11] = 2.5                      # pair 3 re-linearised on another node
    rows["tooth"] = SimpleNamespace(G=moved.tocsr())
    generation = ws.generation
    assert ws.refresh(structure, rows, "tooth") is not None
    assert ws.generation == generation + 1
    check(np.array([3, 4, 12]))
