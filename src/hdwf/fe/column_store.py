"""Columns of K^-1 (responses on the watch dofs) stored one per contiguous row, in shared chunks.

The contact solver's working set (``working_set``), its friction cache (``friction``) and the
kept tooth-node loads (``node_columns``) all keep columns this way.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

CHUNK_ROWS = 128   # columns per chunk: 128 x 19 108 watch dofs (HD 42, default mesh) is 20 MB


class ColumnStore:
    """Columns K^-1 G^T (nwatch long) by working-set position, stored one per row.

    A PDAS iterate combines only the columns of its active pairs (a fifth of the working set,
    typically); with a column per contiguous row that product reads just those rows, about ten
    times faster than multiplying the whole store by a mostly zero vector.

    The rows live in chunks of ``CHUNK_ROWS``.  A store only grows by whole new chunks (no
    copy of what it holds), and a copy shares every chunk with its original until one of
    them writes into it (copy on write): a model forked for each side of the torque test
    keeps the hundreds of megabytes of its mount's columns once, not three times.

    Parameters
    ----------
    nwatch : int
        Length of the watch vector.
    n : int
        Columns in use from the start (zero).
    """

    def __init__(self, nwatch: int, n: int = 0):
        self._nwatch = nwatch
        self._chunks: list[np.ndarray] = []
        self._owned: list[bool] = []       # chunk written by this store only (no copy shares it)
        self.size = 0
        if n:
            self.append(np.zeros((nwatch, n)))

    def copy(self) -> "ColumnStore":
        """An independent store; the chunks are shared until either side writes into one."""
        new = ColumnStore(self._nwatch)
        new._chunks, new.size = list(self._chunks), self.size
        self._owned = [False] * len(self._chunks)
        new._owned = [False] * len(self._chunks)
        return new

    def _writable(self, c: int) -> np.ndarray:
        if not self._owned[c]:
            self._chunks[c] = self._chunks[c].copy()
            self._owned[c] = True
        return self._chunks[c]

    def _used(self, c: int) -> np.ndarray:
        """The rows in use of chunk c."""
        return self._chunks[c][:min(CHUNK_ROWS, self.size - c * CHUNK_ROWS)]

    @property
    def columns(self) -> np.ndarray:
        """The columns in use (nwatch x size; a copy)."""
        if not self._chunks:
            return np.zeros((self._nwatch, 0))
        return np.vstack([self._used(c) for c in range(len(self._chunks))]).T

    def append(self, X: np.ndarray):
        """Add the columns X (nwatch x k) after the last one."""
        k, done = X.shape[1], 0
        while done < k:
            fill = self.size - CHUNK_ROWS * (len(self._chunks) - 1) if self._chunks else CHUNK_ROWS
            if fill == CHUNK_ROWS:
                # empty, not zeros: a row is first touched when it is written
                self._chunks.append(np.empty((CHUNK_ROWS, self._nwatch)))
                self._owned.append(True)
                fill = 0
            m = min(CHUNK_ROWS - fill, k - done)
            self._writable(len(self._chunks) - 1)[fill:fill + m] = X[:, done:done + m].T
            done += m
            self.size += m

    def replace(self, positions: np.ndarray, X: np.ndarray):
        """Renew the columns at ``positions`` with X (nwatch x len(positions))."""
        positions = np.asarray(positions)
        chunk = positions // CHUNK_ROWS
        for c in np.unique(chunk):
            sel = np.flatnonzero(chunk == c)
            self._writable(int(c))[positions[sel] % CHUNK_ROWS] = X[:, sel].T

    def combine(self, positions: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """sum_k weights[k] * column[positions[k]] (nwatch)."""
        positions = np.asarray(positions)
        out = np.zeros(self._nwatch)
        if 3 * len(positions) >= self.size:
            # most of the store (a loaded preload holds ~70 % of its working set active): one
            # pass over it with zero weights elsewhere is twice as fast as gathering the rows
            w = np.bincount(positions, weights, minlength=self.size)
            for c in range(len(self._chunks)):
                rows = self._used(c)
                out += w[c * CHUNK_ROWS:c * CHUNK_ROWS + rows.shape[0]] @ rows
            return out
        chunk = positions // CHUNK_ROWS
        for c in np.unique(chunk):
            sel = np.flatnonzero(chunk == c)
            out += weights[sel] @ self._chunks[c][positions[sel] % CHUNK_ROWS]
        return out

    def right_multiply(self, C: sp.spmatrix | np.ndarray) -> np.ndarray:
        """columns @ C (nwatch x k) for C (size x k)."""
        C = sp.csr_matrix(C)
        out = np.zeros((self._nwatch, C.shape[1]))
        for c in range(len(self._chunks)):
            rows = self._used(c)
            part = C[c * CHUNK_ROWS:c * CHUNK_ROWS + rows.shape[0]]
            if part.nnz:
                out += np.asarray(part.T @ rows).T
        return out

    def project(self, G: sp.csr_matrix, n: int | None = None, start: int = 0) -> np.ndarray:
        """G @ columns[:, start:n] (rows x (n - start)) for sparse rows G, reading only the watch
        entries G touches (a contact row has a handful) instead of copying the whole store."""
        n = self.size if n is None else n
        G = sp.csr_matrix(G)
        # each watch entry read once, though neighbouring rows share nodes
        watched, entry = np.unique(G.indices, return_inverse=True)
        compact = sp.csr_matrix((G.data, entry, G.indptr), shape=(G.shape[0], watched.size))
        out = np.zeros((G.shape[0], max(n - start, 0)))
        # chunk by chunk: the entries of all columns at once were the solve's peak memory (two
        # copies of most of the store on a finely divided flank)
        for c in range(start // CHUNK_ROWS, -(-n // CHUNK_ROWS)):
            lo, hi = max(start, c * CHUNK_ROWS), min(n, (c + 1) * CHUNK_ROWS)
            touched = self._chunks[c][lo - c * CHUNK_ROWS:hi - c * CHUNK_ROWS][:, watched]  # columns x entries
            out[:, lo - start:hi - start] = compact @ np.ascontiguousarray(touched.T)
        return out
