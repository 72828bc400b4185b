"""How the tooth flanks carry tangential force: ``NoFriction`` (the baseline) or ``FlankFriction``.

The contact solver (``solver``) asks its flank law for the dense KKT system of each active
set, for the tangential forces and their displacement once it is solved, and whether the
stick/slip states of a level have settled; the frictionless law answers with the plain
system and no state, so the frictionless path carries no friction terms at all.

Coulomb friction on the FS-CS flanks (``ModelChanges.flank_friction`` = mu): every tooth
pair has a slip row t (tangent to the master segment, ``contact_rows``).  A sliding pair's
force becomes p (n + mu sigma t), sigma = -sign of its slip over the load step; a sticking
pair carries an unknown tangential force (|f_t| <= mu p) and does not slip.  The stick/slip
state of every loaded tooth pair is iterated at each level: a pair coming into contact
slides against its slip; a sticking pair whose tangential force leaves the cone
|f_t| <= mu p slides in the force's direction; a sliding pair whose slip runs with its
friction force sticks.  ``FlankFriction`` keeps its own compliance cache beside the
working set's: the columns K^-1 Gt^T of the slip rows of the working-set pairs and the
blocks G_W K^-1 Gt_W^T and Gt_W K^-1 Gt_W^T.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from hdwf.fe.contact_rows import PairId, Rows, slip_rows_of, stack_slip_rows
from hdwf.fe.column_store import ColumnStore
from hdwf.fe.working_set import AddedPairs, RefreshedPairs, WorkingSet
from hdwf.fe.structure import Structure

FRICTION_MAX_IT = 30     # slip-direction iterations per load level (flank friction)
SLIP_TOL = 1e-7          # mm: a slip below 0.1 nm over a step counts as none
KKT_REGULARISATION = 1e-13   # times the block's largest compliance, added to its diagonal


@dataclass(frozen=True)
class ActiveBlock:
    """The dual system of one active set A (see ``solver``), what a flank law builds on."""
    torque: float
    pairs: list[PairId]          # A, in working-set order
    positions: np.ndarray        # their working-set positions
    rows: np.ndarray             # their rows in the level's stacked operator
    compliance: np.ndarray       # C = G K^-1 G^T + diag(s_ball) on A
    mode_rows: np.ndarray        # H = G R on A
    scale: float                 # largest diagonal of C (regularisation scale)
    gap_rhs: np.ndarray          # -(g0 + T G K^-1 f) on A
    mode_rhs: np.ndarray         # -T R^T f per unit torque
    n_pairs: int                 # pairs of the level


@dataclass(frozen=True)
class KktSystem:
    """KKT matrix and right-hand side of an active set; unknowns (p_A, tangential, alpha)."""
    matrix: np.ndarray
    rhs: np.ndarray
    n_tangential: int            # unknown tangential forces (sticking pairs)
    slide_factor: np.ndarray | None = None   # mu sigma of every active pair
    sticking: np.ndarray | None = None       # indices in A of the sticking pairs


def frictionless_kkt(block: ActiveBlock) -> KktSystem:
    """The frictionless KKT system of an active set.

    Parameters
    ----------
    block : ActiveBlock
        The active set's blocks.

    Returns
    -------
    KktSystem
        [[C, H], [H^T, 0]] [p; alpha] = [-(g0 + T G K^-1 f); -T R^T f], no tangential
        unknowns (the mode block is completed by the solver).
    """
    nA, nm = len(block.pairs), block.mode_rows.shape[1]
    M = np.zeros((nA + nm, nA + nm))
    M[:nA, :nA] = block.compliance
    M[np.arange(nA), np.arange(nA)] += KKT_REGULARISATION * block.scale
    M[:nA, nA:] = block.mode_rows
    M[nA:, :nA] = block.mode_rows.T
    return KktSystem(M, np.concatenate([block.gap_rhs, block.mode_rhs]), 0)


class FrictionlessLevel:
    """One load level without friction: no tangential unknowns, nothing to settle (and no
    tangential displacement: the solver forms u from the normal forces alone)."""

    def kkt(self, block: ActiveBlock) -> KktSystem:
        return frictionless_kkt(block)

    def settle(self, normal_force: np.ndarray, tangential_force: np.ndarray,
               u: np.ndarray) -> bool:
        return True

    def add_slip_twist(self, twist, positions: np.ndarray, tangential_force: np.ndarray):
        return twist


class NoFriction:
    """The frictionless flanks of the baseline: no state and no cache."""

    def copy(self) -> "NoFriction":
        return self

    def pairs_added(self, structure: Structure, rows: dict[str, Rows], added: AddedPairs,
                    working_set: WorkingSet):
        """Nothing to cache."""

    def pairs_refreshed(self, structure: Structure, rows: dict[str, Rows],
                        refreshed: RefreshedPairs, working_set: WorkingSet):
        """Nothing to cache."""

    def start_level(self, rows: dict[str, Rows], ids: list[PairId], R: np.ndarray,
                    u_start: np.ndarray, unit_torque_u_watch: np.ndarray) -> FrictionlessLevel:
        return FrictionlessLevel()

    def finish_level(self, level: FrictionlessLevel):
        """No state to keep."""

    def add_slip_forces(self, forces: np.ndarray, rows: dict[str, Rows],
                        tangential_force: np.ndarray) -> np.ndarray:
        return forces


class FlankFriction:
    """Coulomb friction on the flanks: the slip columns cache and the slide directions.

    Parameters
    ----------
    mu : float
        Friction coefficient.
    nwatch : int
        Length of the watch vector.
    n_pairs : int
        Pairs already in the working set when friction is switched on (none of them is a
        tooth pair, so their slip columns are zero).
    """

    def __init__(self, mu: float, nwatch: int, n_pairs: int = 0):
        self.mu = float(mu)
        self.nwatch = nwatch
        n = n_pairs
        self.store = ColumnStore(nwatch, n)            # K^-1 Gt^T of the working set
        self.twist_columns = np.zeros(n)               # q^T K^-1 Gt^T
        self.normal_slip = np.zeros((n, n))            # G_W K^-1 Gt_W^T
        self.slip_slip = np.zeros((n, n))              # Gt_W K^-1 Gt_W^T
        self.slip_rows = sp.csr_matrix((n, nwatch)) if n else None   # Gt_W
        self.direction: dict[PairId, float] = {}       # slide direction of every tooth pair

    @classmethod
    def sticking_at(cls, mu: float, structure: Structure, rows: dict[str, Rows], working_set: WorkingSet,
                    ids: list[PairId], normal_force: np.ndarray) -> "FlankFriction":
        """Friction switched on at an assembled state (pairs ``ids``, their ``normal_force``)
        whose flanks carry no tangential force: the slip columns of every working-set pair, and
        the loaded tooth pairs sticking there (no slip from that state on until a force leaves
        the cone)."""
        law = cls(mu, structure.nwatch)
        if working_set.pairs:
            law.pairs_added(structure, rows, AddedPairs(list(working_set.pairs), working_set.normal_rows, 0),
                            working_set)
        law.direction = {i: 0.0 for i, p in zip(ids, normal_force) if i[0] == "tooth" and p > 0}
        return law

    @property
    def size(self) -> int:
        """Working-set pairs the cache covers."""
        return self.normal_slip.shape[0]

    def copy(self) -> "FlankFriction":
        new = FlankFriction(self.mu, self.nwatch)
        new.store = self.store.copy()
        new.twist_columns = self.twist_columns.copy()
        new.normal_slip = self.normal_slip.copy()
        new.slip_slip = self.slip_slip.copy()
        new.slip_rows = self.slip_rows
        new.direction = dict(self.direction)
        return new

    def pairs_added(self, structure: Structure, rows: dict[str, Rows], added: AddedPairs,
                    working_set: WorkingSet):
        """Grow the cache by the slip columns of pairs that entered the working set."""
        n0, k = added.first, len(added.ids)
        Tn = slip_rows_of(rows, added.ids, self.nwatch)
        Y, Yq = structure.compliance_columns(Tn)
        self.store.append(Y)
        self.twist_columns = np.concatenate([self.twist_columns, Yq])
        self.slip_rows = Tn if self.slip_rows is None else sp.vstack([self.slip_rows, Tn]).tocsr()
        CWY = np.zeros((n0 + k, n0 + k))      # the slip columns are not symmetric
        CWY[:n0, :n0] = self.normal_slip
        CWY[:, n0:] = np.asarray(working_set.normal_rows @ Y)
        CWY[n0:, :n0] = self.store.project(added.normal_rows, n0)
        self.normal_slip = CWY
        CWYY = np.zeros((n0 + k, n0 + k))
        CWYY[:n0, :n0] = self.slip_slip
        CWYY[:, n0:] = np.asarray(self.slip_rows @ Y)
        CWYY[n0:, :n0] = self.store.project(Tn, n0)
        self.slip_slip = CWYY

    def pairs_refreshed(self, structure: Structure, rows: dict[str, Rows],
                        refreshed: RefreshedPairs, working_set: WorkingSet):
        """Renew the slip columns of pairs whose rows were re-linearised."""
        Y, Yq = structure.compliance_columns(
            slip_rows_of(rows, [(refreshed.kind, b) for b in refreshed.row_indices], self.nwatch))
        self.store.replace(refreshed.positions, Y)
        self.twist_columns[refreshed.positions] = Yq
        self.normal_slip = self.store.project(working_set.normal_rows)
        self.slip_rows = slip_rows_of(rows, working_set.pairs, self.nwatch)
        self.slip_slip = self.store.project(self.slip_rows)

    def start_level(self, rows: dict[str, Rows], ids: list[PairId], R: np.ndarray,
                    u_start: np.ndarray, unit_torque_u_watch: np.ndarray) -> "FrictionLevel":
        """The stick/slip state of a new level: each pair's direction from the last level."""
        slip_rows = stack_slip_rows(rows, self.nwatch)
        tooth = np.array([k == "tooth" for k, _ in ids])
        state = np.array([self.direction.get(i, np.nan) for i in ids])
        return FrictionLevel(friction=self, ids=ids, tooth=tooth, slip_rows=slip_rows,
                             slip_modes=slip_rows @ R, slip_target=slip_rows @ u_start, state=state,
                             unit_torque_u_watch=unit_torque_u_watch)

    def finish_level(self, level: "FrictionLevel"):
        """Keep the settled directions of the tooth pairs for the next level."""
        self.direction = {level.ids[j]: float(level.state[j]) for j in np.flatnonzero(level.tooth)}

    def add_slip_forces(self, forces: np.ndarray, rows: dict[str, Rows],
                        tangential_force: np.ndarray) -> np.ndarray:
        """Contact forces on the watch vector with the friction forces along the flanks."""
        return forces + stack_slip_rows(rows, self.nwatch).T @ tangential_force


FlankLaw = NoFriction | FlankFriction


def flank_law(mu: float, nwatch: int, current: FlankLaw | None = None,
              n_pairs: int = 0) -> FlankLaw:
    """The flank law for friction coefficient ``mu``.

    Parameters
    ----------
    mu : float
        Coulomb coefficient; 0 is the frictionless baseline.
    nwatch : int
        Length of the watch vector.
    current : NoFriction or FlankFriction, optional
        The law of a model that already has ``n_pairs`` working-set pairs: friction keeps
        its cache if it covers them, else starts with zero columns for them.
    n_pairs : int
        Pairs in that model's working set.

    Returns
    -------
    NoFriction or FlankFriction
    """
    if not mu > 0:
        return NoFriction()
    if isinstance(current, FlankFriction) and current.size == n_pairs:
        kept = current.copy()
        kept.mu = float(mu)
        return kept
    return FlankFriction(mu, nwatch, n_pairs)


@dataclass
class FrictionLevel:
    """The stick/slip state of one load level with flank friction.

    ``state`` of every pair: +-1 sliding (tangential force mu p sigma), 0 sticking
    (tangential force unknown, slip over the step = 0), nan not yet in contact (no
    tangential force until its slip is known).
    """
    friction: FlankFriction
    ids: list[PairId]
    tooth: np.ndarray                 # which pairs are tooth pairs
    slip_rows: sp.csr_matrix          # Gt of every pair of the level
    slip_modes: np.ndarray            # Gt R
    slip_target: np.ndarray           # slip at the start of the level
    state: np.ndarray
    unit_torque_u_watch: np.ndarray

    def kkt(self, block: ActiveBlock) -> KktSystem:
        """Unknowns (p_A, lambda_S, alpha): sliding pairs add mu sigma p along the flank,
        sticking pairs S an unknown tangential force with zero slip.

        GY = G_W K^-1 Gt_W^T and YY = Gt_W K^-1 Gt_W^T (the cache), TR = Gt R, ms = mu sigma
        of each active pair, sk the sticking ones among them."""
        GY, YY, TR = self.friction.normal_slip, self.friction.slip_slip, self.slip_modes
        T, wp, rows, C, H = block.torque, block.positions, block.rows, block.compliance, block.mode_rows
        eps = 1e-13 * block.scale
        nA, nm = len(block.pairs), H.shape[1]
        st = self.state[rows]
        ms = self.friction.mu * np.nan_to_num(st)
        sk = np.flatnonzero(st == 0)
        Swp, Srows, nS = wp[sk], rows[sk], sk.size
        n = nA + nS
        M = np.zeros((n + nm, n + nm))
        M[:nA, :nA] = C + GY[np.ix_(wp, wp)] * ms[None, :] + eps * np.eye(nA)
        M[:nA, nA:n] = GY[np.ix_(wp, Swp)]
        M[:nA, n:] = H
        M[nA:n, :nA] = GY[np.ix_(wp, Swp)].T + YY[np.ix_(Swp, wp)] * ms[None, :]
        M[nA:n, nA:n] = YY[np.ix_(Swp, Swp)] + eps * np.eye(nS)
        M[nA:n, n:] = TR[Srows]
        M[n:, :nA] = (H + ms[:, None] * TR[rows]).T
        M[n:, nA:n] = TR[Srows].T
        slip_rhs = self.slip_target[Srows] - T * (self.slip_rows[Srows] @ self.unit_torque_u_watch)
        rhs = np.concatenate([block.gap_rhs, slip_rhs, block.mode_rhs])
        return KktSystem(M, rhs, nS, ms, sk)

    def tangential(self, system: KktSystem, solution: np.ndarray, block: ActiveBlock,
                   u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The displacement with the friction forces' share, and the tangential forces."""
        nA, nS = len(block.pairs), system.n_tangential
        ftA = system.slide_factor * solution[:nA]
        ftA[system.sticking] = solution[nA:nA + nS]
        u = u + self.friction.store.combine(block.positions, ftA)
        ft_full = np.zeros(block.n_pairs)
        ft_full[block.rows] = ftA
        return u, ft_full

    def settle(self, normal_force: np.ndarray, tangential_force: np.ndarray,
               u: np.ndarray) -> bool:
        """Update the stick/slip states from a solution; True if none changed."""
        p_full, ft, state = normal_force, tangential_force, self.state
        slip = self.slip_rows @ u - self.slip_target
        loaded = self.tooth & (p_full > 0)
        new = state.copy()
        new[~loaded] = np.nan
        # a pair coming into contact slides against its slip
        fresh = loaded & np.isnan(state)
        new[fresh] = np.where(np.abs(slip[fresh]) < SLIP_TOL, 0.0, -np.sign(slip[fresh]))
        # sticking pair beyond the cone: slides in the direction of its force
        over = loaded & (state == 0) & (np.abs(ft) > self.friction.mu * p_full * (1 + 1e-9))
        new[over] = np.sign(ft[over])
        # sliding pair whose slip runs with its friction force: it sticks
        back = loaded & (state != 0) & (state * slip > SLIP_TOL)
        new[back] = 0.0
        if np.array_equal(new, state, equal_nan=True):
            return True
        self.state = new
        return False

    def add_slip_twist(self, twist, positions: np.ndarray, tangential_force: np.ndarray):
        """The twist with the share of the friction forces of the working-set pairs."""
        if positions.size:
            twist += self.friction.twist_columns[positions] @ tangential_force
        return twist
