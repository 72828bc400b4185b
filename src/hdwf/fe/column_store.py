"""Columns of K^-1 (responses on the watch dofs) stored one per contiguous row, grown geometrically.

The contact solver's working set (``working_set``), its friction cache (``friction``) and the
kept tooth-node loads (``node_columns``) all keep columns this way.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


class ColumnStore:
    """Columns K^-1 G^T (nwatch long) by working-set position, stored one per row.

    A PDAS iterate combines only the columns of its active pairs (a fifth of the working set,
    typically); with a column per contiguous row that product reads just those rows, about ten
    times faster than multiplying the whole store by a mostly zero vector.

    Parameters
    ----------
    nwatch : int
        Length of the watch vector.
    n : int
        Columns in use from the start (zero).
    """

    def __init__(self, nwatch: int, n: int = 0):
        self._rows = np.zeros((n, nwatch))
        self.size = n

    def copy(self) -> "ColumnStore":
        new = ColumnStore(self._rows.shape[1])
        new._rows, new.size = self._rows.copy(), self.size
        return new

    @property
    def columns(self) -> np.ndarray:
        """The columns in use (nwatch x size; a view)."""
        return self._rows[:self.size].T

    def append(self, X: np.ndarray):
        """Add the columns X (nwatch x k) after the last one (storage grown geometrically)."""
        n0, k = self.size, X.shape[1]
        if n0 + k > self._rows.shape[0]:
            grown = np.zeros((max(2 * self._rows.shape[0], n0 + k, 256), self._rows.shape[1]))
            grown[:n0] = self._rows[:n0]
            self._rows = grown
        self._rows[n0:n0 + k] = X.T
        self.size = n0 + k

    def replace(self, positions: np.ndarray, X: np.ndarray):
        """Renew the columns at ``positions`` with X (nwatch x len(positions))."""
        self._rows[positions] = X.T

    def combine(self, positions: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """sum_k weights[k] * column[positions[k]] (nwatch)."""
        if 3 * len(positions) >= self.size:
            # most of the store (a loaded preload holds ~70 % of its working set active): one
            # pass over it with zero weights elsewhere is twice as fast as gathering the rows
            return np.bincount(positions, weights, minlength=self.size) @ self._rows[:self.size]
        return weights @ self._rows[positions]

    def project(self, G: sp.csr_matrix, n: int | None = None, start: int = 0) -> np.ndarray:
        """G @ columns[:, start:n] (rows x (n - start)) for sparse rows G, reading only the watch
        entries G touches (a contact row has a handful) instead of copying the whole store."""
        n = self.size if n is None else n
        G = sp.csr_matrix(G)
        # each watch entry read once, though neighbouring rows share nodes
        watched, entry = np.unique(G.indices, return_inverse=True)
        touched = self._rows[start:n][:, watched]            # (n - start) x entries touched
        compact = sp.csr_matrix((G.data, entry, G.indptr), shape=(G.shape[0], watched.size))
        return np.asarray(compact @ np.ascontiguousarray(touched.T))
