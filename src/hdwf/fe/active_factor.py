"""The dense KKT solves of an active set, and the Cholesky factor of its compliance, kept while
only part of its diagonal moves.

The frictionless KKT solve of an active set factorises C = G K^-1 G^T + diag(s) of its pairs
(``solve_saddle``).  Within one load level the Hertz secants of the balls and the flank
layer's shares are iterated, and each pass solves the same active pairs again with a new s: on a
loaded HD 42 section (hd42-lhs-01, studies' model) 365 of its 1050 active pairs (5 balls, 360
tooth pairs, the same ones pass after pass) change their s, the others keep it to the last bit,
and the off-diagonal part G K^-1 G^T does not change until the rows are re-linearised
(``WorkingSet.generation``).  Refactorising all of C each pass took 1.3 s of that design's 9 s
profiled solve.

So the pairs whose s moved are ordered last (*volatile*, V), the others first (*stable*, P):

    C = [[C_PP, C_PV], [C_VP, C_VV]],  L11 = chol(C_PP),  W = L11^-1 C_PV,  S = C_VV - W^T W,

and a later block of the same generation that holds every stable pair with its s unchanged
needs only chol(S + the change of diag(s) on V), and W and S for its pairs new to V: about
(|V| / |C|)^3 of a factorisation.  Otherwise (a stable pair left the set or changed its s, or
V has grown past half the block) the block is factorised anew with V the pairs that moved
last.  The solutions equal a direct Cholesky solve to round-off; the 1e-13 regularisation the
KKT matrix adds to C (``friction.frictionless_kkt``) is kept at its value of the factorisation
on P.  Hand-written: LAPACK has no Cholesky update for a changed diagonal.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.linalg import cho_factor, cho_solve, cholesky, solve_triangular

REBUILD_VOLATILE_FRACTION = 0.5   # factorise anew once V holds more of the block than this
# smaller blocks are factorised directly: below ~400 pairs (the coarse meshes of the validation
# campaigns) a Cholesky costs less than the bookkeeping of the kept factor
MIN_KEPT_PAIRS = 400


@dataclass
class _Kept:
    """The factor of one generation's stable pairs and the Schur complement of its volatile ones."""
    stable: np.ndarray            # working-set positions of P, in the factor's order
    stable_diag: np.ndarray       # diag(C_PP) (without the regularisation) at the factorisation
    L11: np.ndarray               # lower Cholesky factor of C_PP
    volatile: np.ndarray          # working-set positions with a column of W and a row of S
    W: np.ndarray                 # L11^-1 C_PV (|P| x |V|)
    S: np.ndarray | None          # C_VV - W^T W with the diagonal of when each pair entered
    volatile_diag: np.ndarray     # that diagonal (without the regularisation)
    L22: np.ndarray | None = None     # the factorisation's chol(S) (S is formed from it when needed)
    regularisation: np.ndarray | None = None   # ... and the regularisation S had then


class BlockSolve:
    """C^-1 B for C = [[L11, 0], [W^T, L22]] [[L11^T, W], [0, L22^T]] in the block's own order."""

    def __init__(self, L11: np.ndarray, W: np.ndarray, L22: np.ndarray, at_stable: np.ndarray,
                 at_volatile: np.ndarray):
        self._L11, self._W, self._L22 = L11, W, L22
        self._at_stable, self._at_volatile = at_stable, at_volatile

    def __call__(self, B: np.ndarray) -> np.ndarray:
        X = np.empty(B.shape)
        if not self._at_stable.size:
            X[self._at_volatile] = cho_solve((self._L22, True), B[self._at_volatile], check_finite=False)
            return X
        y = solve_triangular(self._L11, B[self._at_stable], lower=True, check_finite=False)
        x_v = np.zeros((0,) + B.shape[1:])
        if self._at_volatile.size:
            z = B[self._at_volatile] - self._W.T @ y
            x_v = cho_solve((self._L22, True), z, check_finite=False)
            y = y - self._W @ x_v
        X[self._at_stable] = solve_triangular(self._L11, y, lower=True, trans="T", check_finite=False)
        X[self._at_volatile] = x_v
        return X


def _cholesky(A: np.ndarray) -> np.ndarray:
    """Lower Cholesky factor (an empty block has an empty one)."""
    return cholesky(A, lower=True, check_finite=False) if A.size else np.zeros(A.shape)


class ActiveFactor:
    """Factors of the active blocks of one solver (see the module docstring).

    ``solver(C, positions, diag, working_set)`` returns C^-1 as a function of the block C (its
    pairs at the ascending working-set ``positions``, in that order; ``diag`` its diagonal without
    the regularisation, which is what is compared from block to block): a ``BlockSolve`` of the
    kept factor, or a direct Cholesky solve for a block of fewer than ``min_pairs`` pairs.  It
    raises ``numpy.linalg.LinAlgError`` when C is not positive definite.
    """

    def __init__(self, min_pairs: int = MIN_KEPT_PAIRS):
        self.min_pairs = min_pairs         # smaller blocks: a direct Cholesky, nothing kept
        self._kept: _Kept | None = None
        self._last_diag = np.zeros(0)      # diag(C) (without regularisation) by position, NaN: unseen
        self._source: tuple[object, int] | None = None   # (working set, generation) of the blocks
        self.factorisations = 0            # full ones (for the tests)
        self.updates = 0                   # reuses of the stable factor

    def copy(self) -> "ActiveFactor":
        """A fresh factor: a forked solver's blocks factorise anew (nothing is shared)."""
        return ActiveFactor(self.min_pairs)

    def solver(self, C: np.ndarray, positions: np.ndarray, diag: np.ndarray,
               working_set: object) -> Callable[[np.ndarray], np.ndarray]:
        if positions.size < self.min_pairs:
            factor = cho_factor(C, lower=True, check_finite=False)
            return lambda B: cho_solve(factor, B, check_finite=False)
        moved = self._moved(positions, diag, working_set)
        kept = self._kept
        if kept is not None and self._reusable(kept, positions, diag):
            return self._update(kept, C, positions, diag)
        return self._factorise(C, positions, diag, moved)

    # ------------------------------------------------------------------ which pairs moved

    def _moved(self, positions: np.ndarray, diag: np.ndarray, working_set) -> np.ndarray:
        """Whether each pair's diagonal differs from its last one (a pair new to the block or to
        the working set's generation counts as moved); remembers the new diagonal."""
        source = self._source
        if source is None or source[0] is not working_set or source[1] != working_set.generation:
            self._source, self._kept = (working_set, working_set.generation), None
            self._last_diag = np.full(0, np.nan)
        if positions.size and positions.max() >= self._last_diag.size:
            grown = np.full(max(2 * self._last_diag.size, positions.max() + 1), np.nan)
            grown[:self._last_diag.size] = self._last_diag
            self._last_diag = grown
        moved = ~(self._last_diag[positions] == diag)
        self._last_diag[positions] = diag
        return moved

    @staticmethod
    def _reusable(kept: _Kept, positions: np.ndarray, diag: np.ndarray) -> bool:
        at = np.searchsorted(positions, kept.stable)      # (a kept factor has stable pairs)
        holds = at.max() < positions.size and np.array_equal(positions[at], kept.stable)
        if not holds or not np.array_equal(diag[at], kept.stable_diag):
            return False
        return positions.size - kept.stable.size <= REBUILD_VOLATILE_FRACTION * positions.size

    # ------------------------------------------------------------------ factor anew

    def _factorise(self, C: np.ndarray, positions: np.ndarray, diag: np.ndarray,
                   moved: np.ndarray) -> BlockSolve:
        self.factorisations += 1
        self._kept = None                  # (until this factorisation has succeeded)
        at_p, at_v = np.flatnonzero(~moved), np.flatnonzero(moved)
        # one Cholesky of C with P first: its leading block is L11, the rows below it W^T, and
        # the trailing block chol(S)
        order = np.concatenate([at_p, at_v])
        L = _cholesky(C.take(order, axis=0).take(order, axis=1))
        f = at_p.size
        L11, W, L22 = np.array(L[:f, :f]), np.array(L[f:, :f].T), np.array(L[f:, f:])
        if f:                              # a block that moved everywhere has nothing to keep
            self._kept = _Kept(positions[at_p], diag[at_p], L11, positions[at_v], W, None, diag[at_v],
                               L22, C[at_v, at_v] - diag[at_v])
        return BlockSolve(L11, W, L22, at_p, at_v)

    # ------------------------------------------------------------------ reuse the stable factor

    def _update(self, kept: _Kept, C: np.ndarray, positions: np.ndarray, diag: np.ndarray) -> BlockSolve:
        self.updates += 1
        if kept.S is None:                 # the first reuse: S from the factorisation's chol(S)
            kept.S = kept.L22 @ kept.L22.T - np.diag(kept.regularisation)
            kept.L22 = kept.regularisation = None
        at_p = np.searchsorted(positions, kept.stable)
        is_stable = np.zeros(positions.size, dtype=bool)
        is_stable[at_p] = True
        at_v = np.flatnonzero(~is_stable)
        self._extend(kept, C, positions, at_p, at_v, diag)
        cols = np.searchsorted(kept.volatile, positions[at_v])
        S = kept.S[np.ix_(cols, cols)]
        # the kept diagonal out, this block's in (its s and its regularisation)
        S[np.diag_indices_from(S)] += C[at_v, at_v] - kept.volatile_diag[cols]
        return BlockSolve(kept.L11, kept.W[:, cols], _cholesky(S), at_p, at_v)

    @staticmethod
    def _extend(kept: _Kept, C: np.ndarray, positions: np.ndarray, at_p: np.ndarray,
                at_v: np.ndarray, diag: np.ndarray) -> None:
        """Keep W and S for exactly the block's volatile pairs: those that left it are dropped (S
        has no entries of them against newcomers), the newcomers get their columns of W and
        rows of S.  Kept in ascending position, as the block is ordered."""
        here = np.isin(kept.volatile, positions[at_v])
        if not here.all():
            kept.volatile, kept.W = kept.volatile[here], kept.W[:, here]
            kept.S, kept.volatile_diag = kept.S[np.ix_(here, here)], kept.volatile_diag[here]
        new = at_v[~np.isin(positions[at_v], kept.volatile)]
        if not new.size:
            return
        old = np.searchsorted(positions, kept.volatile)
        W_new = solve_triangular(kept.L11, C[np.ix_(at_p, new)], lower=True, check_finite=False)
        m, k = kept.volatile.size, new.size
        S = np.empty((m + k, m + k))
        S[:m, :m] = kept.S
        S[:m, m:] = C[np.ix_(old, new)] - kept.W.T @ W_new
        S[m:, :m] = S[:m, m:].T
        S[m:, m:] = C[np.ix_(new, new)] - W_new.T @ W_new
        S[m + np.arange(k), m + np.arange(k)] -= C[new, new] - diag[new]   # without the regularisation
        order = np.argsort(np.concatenate([kept.volatile, positions[new]]))
        kept.volatile = np.concatenate([kept.volatile, positions[new]])[order]
        kept.W = np.concatenate([kept.W, W_new], axis=1)[:, order]
        kept.S = S[np.ix_(order, order)]
        kept.volatile_diag = np.concatenate([kept.volatile_diag, diag[new]])[order]


Solve = Callable[[np.ndarray], np.ndarray]    # B -> C^-1 B


def solve_frictionless_kkt(M: np.ndarray, rhs: np.ndarray, n: int,
                           factor: Callable[[np.ndarray], Solve]) -> np.ndarray:
    """M^-1 rhs for a frictionless KKT matrix [[C, H], [H^T, E]] (n rows of C): through the
    Cholesky factor of its positive definite C (``factor``) and the small Schur complement of the
    modes, half the work of an LU of M; by ``solve_kkt`` if C is not positive definite."""
    try:
        solve = factor(M[:n, :n])
    except np.linalg.LinAlgError:
        return solve_kkt(M, rhs)
    return solve_saddle(solve, M, rhs, n)


def solve_kkt(M: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """M^-1 rhs by LU (friction, or a C that is not positive definite), and a singular M (an
    unheld mode) by least squares."""
    try:
        return np.linalg.solve(M, rhs)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(M, rhs, rcond=None)[0]


def solve_saddle(solve: Solve, M: np.ndarray, rhs: np.ndarray, n: int) -> np.ndarray:
    """[[C, H], [H^T, E]] [p; alpha] = [r; s] with ``solve`` = C^-1: p = C^-1 (r - H alpha),
    (H^T C^-1 H - E) alpha = H^T C^-1 r - s."""
    H, E = M[:n, n:], M[n:, n:]
    if H.shape[1] == 0:
        return solve(rhs[:n])
    Ci = solve(np.column_stack([rhs[:n], H]))
    Ci_r, Ci_H = Ci[:, 0], Ci[:, 1:]
    alpha = np.linalg.solve(H.T @ Ci_H - E, H.T @ Ci_r - rhs[n:])
    return np.concatenate([Ci_r - Ci_H @ alpha, alpha])
