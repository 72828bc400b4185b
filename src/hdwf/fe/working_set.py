"""The working set of the contact solver: the pairs whose compliance is known, and that compliance.

For a contact pair i the compliance column x_i = K^-1 G_i^T is obtained by back-substitution
only when the pair first enters the working set, and reused over all later iterations and
load steps; the working set also keeps the compliance among its pairs, C_ij = G_i K^-1 G_j^T,
grown by the new columns, and the twist of every column, q^T x_i.  A pair never leaves the
working set; only its linearisation can be renewed (``refresh``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from hdwf.fe.column_store import ColumnStore
from hdwf.fe.contact_rows import PairId, Rows
from hdwf.fe.structure import Structure


@dataclass(frozen=True)
class AddedPairs:
    """Pairs that just entered the working set."""
    ids: list[PairId]
    normal_rows: sp.csr_matrix    # their rows G
    first: int                    # working-set position of the first of them


@dataclass(frozen=True)
class RefreshedPairs:
    """Working-set pairs of one kind whose rows were renewed."""
    kind: str
    positions: np.ndarray         # their working-set positions
    row_indices: list[int]        # their row indices in the rows of that kind


class WorkingSet:
    """Working-set pairs with their cached compliance columns (see the module docstring).

    Parameters
    ----------
    nwatch : int
        Length of the watch vector.
    """

    def __init__(self, nwatch: int):
        self.pairs: list[PairId] = []
        self.position: dict[PairId, int] = {}
        self.store = ColumnStore(nwatch)            # K^-1 G^T on the watch dofs, by position
        self.twist_columns = np.zeros(0)            # q^T K^-1 G^T
        self.normal_rows: sp.csr_matrix | None = None   # G of the pairs, by position
        self.compliance = np.zeros((0, 0))          # G K^-1 G^T among the pairs, exactly symmetric
        self.generation = 0                         # counts refreshes: cached projections are stale

    def copy(self) -> "WorkingSet":
        """An independent copy (the rows matrix is never changed in place, so it is shared)."""
        new = WorkingSet(0)
        new.pairs, new.position = list(self.pairs), dict(self.position)
        new.store = self.store.copy()
        new.twist_columns = self.twist_columns.copy()
        new.normal_rows = self.normal_rows
        new.compliance = self.compliance.copy()
        new.generation = self.generation
        return new

    def add(self, structure: Structure, rows: dict[str, Rows],
            ids: list[PairId]) -> AddedPairs | None:
        """Enter the pairs ``ids`` not yet in the working set; None if there are none."""
        ids = [i for i in ids if i not in self.position]
        if not ids:
            return None
        Gn = sp.vstack([rows[k].G[i] for k, i in ids]).tocsr()
        X, Xq = structure.compliance_columns(Gn)
        n0, k = len(self.pairs), len(ids)
        self.store.append(X)
        for i in ids:
            self.position[i] = len(self.pairs)
            self.pairs.append(i)
        self.twist_columns = np.concatenate([self.twist_columns, Xq])
        # compliance among the working set, grown by the new columns
        self.normal_rows = Gn if self.normal_rows is None else sp.vstack([self.normal_rows,
                                                                          Gn]).tocsr()
        newcols = np.asarray(self.normal_rows @ X)
        CW = np.zeros((n0 + k, n0 + k))
        CW[:n0, :n0] = self.compliance
        CW[:n0, n0:] = newcols[:n0]
        CW[n0:, :n0] = newcols[:n0].T
        CW[n0:, n0:] = _symmetric(newcols[n0:])
        self.compliance = CW
        return AddedPairs(ids, Gn, n0)

    def refresh(self, structure: Structure, rows: dict[str, Rows],
                kind: str) -> RefreshedPairs | None:
        """Renew the columns of the pairs of ``kind`` after a new linearisation of its rows
        (same count); None if none of them is in the working set or none of their rows
        changed.  Only pairs whose row changed are back-substituted (the others' columns
        are the same numbers), which keeps the preload ramp's re-linearisations cheap."""
        idx = [(self.position[(k, i)], i) for (k, i) in self.pairs if k == kind]
        if not idx:
            return None
        pos = np.array([a for a, _ in idx])
        row_indices = [b for _, b in idx]
        delta = abs(rows[kind].G[row_indices] - self.normal_rows[pos]).max(axis=1).toarray().ravel()
        changed = np.flatnonzero(delta > 0)
        if changed.size == 0:
            return None
        pos, row_indices = pos[changed], [row_indices[j] for j in changed]
        X, Xq = structure.compliance_columns(rows[kind].G[row_indices])
        self.store.replace(pos, X)
        self.twist_columns[pos] = Xq
        self.normal_rows = sp.vstack([rows[k].G[i] for k, i in self.pairs]).tocsr()
        self.compliance = _symmetric(self.store.project(self.normal_rows))
        self.generation += 1
        return RefreshedPairs(kind, pos, row_indices)


def _symmetric(C: np.ndarray) -> np.ndarray:
    """(C + C^T) / 2: G K^-1 G^T is symmetric but its back-substituted columns only to
    round-off, and the active blocks cut from it are factorised by Cholesky."""
    return 0.5 * (C + C.T)


class ProjectedColumns:
    """G K^-1 G_W^T: one level's rows G times the working set's columns, grown with the set.

    An active-set iterate checks the gap of every candidate row, G u with u = sum_k p_k x_k over
    its active pairs.  Forming u reads a whole watch-length column per active pair; with every
    tooth engaged (hundreds of active pairs, ~20 000 watch dofs) that gather dominated the
    solve.  The projections G x_k are rows long (a quarter of the watch length), are made once
    per level and column (``ColumnStore.project`` reads only the entries G touches), and are
    renewed whole when the working set's columns are (``WorkingSet.generation``).

    Parameters
    ----------
    G : scipy.sparse.csr_matrix
        The level's stacked rows.
    """

    def __init__(self, G: sp.csr_matrix):
        self.G = G
        self.store = ColumnStore(G.shape[0])
        self.generation = -1

    def copy(self) -> "ProjectedColumns":
        """An independent copy (for a copied working set: same columns, same generation)."""
        new = ProjectedColumns(self.G)
        new.store, new.generation = self.store.copy(), self.generation
        return new

    def combine(self, working_set: WorkingSet, positions: np.ndarray,
                weights: np.ndarray) -> np.ndarray:
        """G sum_k weights[k] x[positions[k]] (rows long), the working set's new columns
        projected first."""
        if self.generation != working_set.generation or working_set.store.size < self.store.size:
            self.store, self.generation = ColumnStore(self.G.shape[0]), working_set.generation
        n0 = self.store.size
        if working_set.store.size > n0:
            self.store.append(working_set.store.project(self.G, start=n0))
        return self.store.combine(positions, weights)
