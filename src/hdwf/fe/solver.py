"""The contact solver (hand-written): a dual Schur-complement / active-set method.

Each body is factorised ONCE (CHOLMOD sparse Cholesky, ``bodies``).  For a contact pair i the
compliance column x_i = K^-1 G_i^T is obtained by back-substitution only when the pair
first enters the working set, and reused over all later iterations and load steps
(``working_set``).  On the working set the small dense mixed LCP

    g = g0 + G K^-1 f + C p + H alpha >= 0,  p >= 0,  p.g = 0,  H^T p = -R^T f,
    C = G K^-1 G^T + diag(s_ball),  H = G R

is solved exactly by a primal-dual active-set (PDAS) iteration: solve the KKT system of
the current active set, drop pairs with tensile p, add every candidate with penetration,
repeat until no pair has p < 0 and the largest penetration of all candidate pairs is
< ``tol_gap`` (1e-5 mm = 0.01 um).  Candidates outside the working set are checked every
iteration with their gaps G u, so no violated pair can be missed; without friction G u comes
from the working set's columns projected on the level's rows (``ProjectedColumns``).
A free rigid mode that is loaded but not yet held (the FS rotation under torque while the
teeth are apart) is closed by adding the first pair that closes along that mode.  A mode
held only weakly (e.g. by two near-radial tip contacts of a relieved, lightly preloaded
section) makes the iterate swing it far (radians) and penetrate hundreds of pairs by
millimetres, far outside the linearised rows; such an iterate (a loaded free mode and a
pair that was open at the current point penetrated by more than ``max_overshoot``) is not
taken: as in a primal active-set method the step stops where the first open pair closes
(ratio test), that pair enters the active set and nothing is dropped.
Around the PDAS, the Hertz secants s_ball of the balls are iterated to 0.1 % of the ball
loads, with a flank layer its compliance at every tooth pair (the pair's share of the
overlap integral depends on its neighbours' gaps) until no approach s p moves by more than the
gap tolerance, and with flank friction the stick/slip states of the tooth pairs (``friction``).
A level is solved at a torque (load control) or at a prescribed rim twist (``Twist``,
displacement control): the torque is then one more unknown, T u_T its displacement (u_T the
unit-torque response), with the equation q^T u = theta; scaled by the rim's load factor that
row is the transpose of its column, so the KKT system stays symmetric.  A preloaded section
that snaps between two equilibria under a torque has one state at a twist.
Cost: one factorisation per body plus back-solves, a handful of dense KKT solves per
load step.  A level that does not converge raises ``ContactFailure``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from hdwf.drive.geometry import ARCMIN
from hdwf.fe.active_factor import ActiveFactor, Solve, solve_frictionless_kkt, solve_kkt
from hdwf.fe.contact_rows import PairId, Rows, stack_rows
from hdwf.fe.flank_layer import LayerEdges, LayerIteration
from hdwf.fe.friction import (FRICTION_MAX_IT, ActiveBlock, FlankLaw, FrictionLevel, NoFriction,
                              FrictionlessLevel)
from hdwf.fe.structure import ModeName, RigidModes, Structure
from hdwf.fe.working_set import ProjectedColumns, WorkingSet

TOL_GAP = 1e-5          # mm: 0.01 um allowed penetration

Level = FrictionlessLevel | FrictionLevel


class ContactFailure(RuntimeError):
    """The contact problem of a load level did not converge."""


@dataclass(frozen=True)
class Twist:
    """A prescribed rim twist (rad): the level's torque is then an unknown (displacement control)."""
    rad: float


def describe(load: "float | Twist") -> str:
    """A level's load for messages: its torque (N m) or its prescribed twist (arcmin)."""
    if isinstance(load, Twist):
        return f"twist={load.rad / ARCMIN:.4g} arcmin"
    return f"T={load / 1000:.4g} N m"


@dataclass(frozen=True)
class SolverSettings:
    """Limits of the active-set iteration.

    ``add_min`` and ``add_frac``: violated pairs added per iteration, the most violated
    first (full switching cycles when a near-mechanism makes one iterate overshoot).
    ``max_overshoot``: with a loaded free rigid mode, an iterate that penetrates a pair
    open at the current point by more than this is replaced by a ratio-test step to the
    first closing pair (see the module docstring); infinite = never.
    """
    max_iter: int = 200          # active-set iterations per PDAS solve
    tol_gap: float = TOL_GAP     # mm: largest penetration accepted
    add_min: int = 5
    add_frac: float = 0.2
    max_overshoot: float = np.inf   # mm: a loaded-mode iterate penetrating an open pair by
                                    # more is cut back to the first closing pair (ratio test)


@dataclass(frozen=True)
class LevelSolution:
    """The contact solution at one torque; arrays are per pair of ``pair_ids``."""
    normal_force: np.ndarray      # p (N)
    tangential_force: np.ndarray  # friction force along the flank (N); zero without friction
    mode_amplitude: np.ndarray    # alpha of the free rigid modes
    u_watch: np.ndarray           # displacement on the watch vector (mm)
    gap: np.ndarray               # g0 + G u (+ Hertz approach of the balls) (mm)
    pair_ids: list[PairId]
    twist: float                  # rim twist q^T u (rad)
    active: frozenset[PairId]     # pairs in contact (warm start of the next level)
    torque: float = float("nan")  # torque on the rim (N mm): given, or solved for at a ``Twist``
    row_compliance: np.ndarray | None = None   # the layer's compliance of every pair at this level


@dataclass(frozen=True)
class _LevelProblem:
    """What every iteration of one level needs: the stacked rows and the free modes."""
    structure: Structure
    rows: dict[str, Rows]
    torque: float
    G: sp.csr_matrix
    g0: np.ndarray
    ids: list[PairId]
    id_position: dict[PairId, int]
    modes: RigidModes
    mode_names: list[ModeName]
    mode_gap_rates: np.ndarray    # GR = G R
    mode_block: np.ndarray        # E of the KKT system's mode rows (``_control``)
    mode_target: np.ndarray       # right-hand side of the mode rows beyond -T R^T f
    ball_index: np.ndarray        # positions of the ball pairs in ``ids``
    row_compliance: np.ndarray    # constant compliance in series with each pair (flank layer)
    tooth_index: np.ndarray       # positions of the tooth pairs in ``ids`` (row order)
    u_start: np.ndarray           # last level's displacement (or the free torque response)
    free_gap: np.ndarray          # g0 + G u_start
    projected: ProjectedColumns   # G K^-1 G_W^T, the gaps of a frictionless iterate
    label: str                    # the load, for messages (``describe``)
    torque_unknown: bool          # at a ``Twist``: the torque is the last mode amplitude


@dataclass(frozen=True)
class _ActiveSetOutcome:
    p: np.ndarray
    ft: np.ndarray
    alpha: np.ndarray
    u: np.ndarray | None          # formed only for the Hertz loop's last outcome without friction
    gap: np.ndarray
    converged: bool
    positions: np.ndarray         # working-set positions of the active pairs ...
    p_active: np.ndarray          # ... and their forces (what u is formed from)
    row_compliance: np.ndarray | None = None   # the compliance in series with each pair it was solved with


@dataclass
class ContactSolver:
    """The solver's state across load levels of one model.

    ``last_u`` (the last level's displacement) and ``ball_loads`` (for the Hertz secants)
    warm-start the next level; ``iterations`` counts active-set iterations.
    """
    settings: SolverSettings
    ball_compliance: float                # c of delta = c P^(2/3) of one ball
    working_set: WorkingSet
    friction: FlankLaw
    iterations: int = 0
    last_u: np.ndarray | None = None
    ball_loads: np.ndarray | None = None
    projected: ProjectedColumns | None = None   # of the last level, kept while its rows stay
    layer_state: tuple[LayerEdges, np.ndarray] | None = None   # the last level's tooth layer and its compliances
    active_factor: ActiveFactor = field(default_factory=ActiveFactor)   # the frictionless blocks' factors

    def copy(self) -> "ContactSolver":
        """An independent copy of the state (working set and friction cache copied)."""
        return replace(self, working_set=self.working_set.copy(), friction=self.friction.copy(),
                       projected=None if self.projected is None else self.projected.copy(),
                       active_factor=self.active_factor.copy())

    def enter(self, structure: Structure, rows: dict[str, Rows], ids: list[PairId]):
        """Enter pairs into the working set (and the friction cache)."""
        added = self.working_set.add(structure, rows, ids)
        if added is not None:
            self.friction.pairs_added(structure, rows, added, self.working_set)

    def refresh(self, structure: Structure, rows: dict[str, Rows], kind: str):
        """Renew the cached columns of the working-set pairs of ``kind`` (new rows)."""
        refreshed = self.working_set.refresh(structure, rows, kind)
        if refreshed is not None:
            self.friction.pairs_refreshed(structure, rows, refreshed, self.working_set)

    # ---------------------------------------------------------------- one load level
    def solve_level(self, structure: Structure, rows: dict[str, Rows], modes: list[ModeName],
                    torque: "float | Twist", active: frozenset[PairId] | None) -> LevelSolution:
        """Solve the contact problem at one torque (N mm) or prescribed twist, warm-started from ``active``
        (and the last displacement); Hertz secants of the balls iterated to 0.1 %, and the
        stick/slip states of the flanks with friction.

        Parameters
        ----------
        structure : Structure
            The bodies and the watch vector.
        rows : dict[str, Rows]
            Every contact row, by kind.
        modes : list of (body, mode)
            The free rigid modes.
        torque : float or Twist
            Torque on the FS rim (N mm), or the rim twist (``Twist``; needs the FS rotation
            among ``modes`` and frictionless flanks): the torque is then solved for.
        active : frozenset, optional
            Pairs in contact at the start (the last level's ``active``).

        Returns
        -------
        LevelSolution
        """
        problem = self._level_problem(structure, rows, modes, torque)
        act = set() if active is None else set(active)
        # initial: every violated pair at zero contact force
        act |= {problem.ids[j] for j in np.flatnonzero(problem.free_gap < -self.settings.tol_gap)}
        level = self.friction.start_level(rows, problem.ids, problem.modes.watch, problem.u_start,
                                          structure.unit_torque_u_watch)
        for _ in range(FRICTION_MAX_IT):
            outcome, act = self._hertz_loop(problem, act, level)
            if level.settle(outcome.p, outcome.ft, outcome.u):
                break
        else:
            raise ContactFailure("flank friction: stick/slip states did not settle in "
                                 f"{FRICTION_MAX_IT} iterations at {describe(torque)}")
        self.friction.finish_level(level)
        self.last_u = outcome.u
        return self._solution(problem, outcome, act, level)

    def _level_problem(self, structure: Structure, rows: dict[str, Rows],
                       modes: list[ModeName], load: "float | Twist") -> _LevelProblem:
        stacked = stack_rows(rows)
        G, g0, ids = stacked.G, stacked.g0, stacked.ids
        rigid, block, target, torque = self._control(structure, modes, load)
        u0 = torque * structure.unit_torque_u_watch if self.last_u is None else self.last_u
        if self.projected is None or not _same_rows(self.projected.G, G):
            self.projected = ProjectedColumns(G)
        return _LevelProblem(
            structure=structure, rows=rows, torque=torque, G=G, g0=g0, ids=ids,
            id_position={i: j for j, i in enumerate(ids)}, modes=rigid, mode_names=modes,
            mode_gap_rates=G @ rigid.watch, mode_block=block, mode_target=target,
            ball_index=np.array([j for j, (k, _) in enumerate(ids) if k == "ball"]),
            row_compliance=stacked.compliance,
            tooth_index=np.array([j for j, (k, _) in enumerate(ids) if k == "tooth"], dtype=np.int64),
            u_start=u0, free_gap=g0 + G @ u0, projected=self.projected, label=describe(load),
            torque_unknown=isinstance(load, Twist))

    def _control(self, structure: Structure, modes: list[ModeName], load: "float | Twist"
                 ) -> tuple[RigidModes, np.ndarray, np.ndarray, float]:
        """The free modes, the KKT mode block E, the mode rows' target and the known torque.

        At a torque: E = -1e-14 I (keeps unheld, unloaded modes at zero), no target.  At a
        ``Twist``: the torque is one more mode, T u_T on the watch dofs, and the known torque
        is 0; its row is f_scale (q^T u - theta) = 0, whose entries are those of its column
        (G u_T = f_scale q^T K^-1 G^T, and R^T f = f_scale q^T R per unit torque), with
        f_scale q^T u_T on the diagonal."""
        rigid = structure.rigid_modes(modes)
        nm = len(modes)
        if not isinstance(load, Twist):
            return rigid, -1e-14 * np.eye(nm), np.zeros(nm), float(load)
        if ("fs", "rot") not in modes:
            raise ValueError("a prescribed twist needs the FS rotation among the free modes")
        if not isinstance(self.friction, NoFriction):
            raise ValueError("a prescribed twist is solved for frictionless flanks only")
        block = np.zeros((nm + 1, nm + 1))
        block[:nm, :nm] = -1e-14 * np.eye(nm)
        block[:nm, nm] = block[nm, :nm] = rigid.load
        block[nm, nm] = structure.f_scale * structure.unit_torque_twist
        target = np.zeros(nm + 1)
        target[nm] = structure.f_scale * load.rad
        torque_mode = RigidModes(np.column_stack([rigid.watch, structure.unit_torque_u_watch]),
                                 np.append(rigid.twist, structure.unit_torque_twist), np.zeros(nm + 1))
        return torque_mode, block, target, 0.0

    def _solution(self, problem: _LevelProblem, outcome: _ActiveSetOutcome, act: set[PairId],
                  level: Level) -> LevelSolution:
        """The level's solution with its twist q^T u from the cached twist columns."""
        ws, ids, idpos = self.working_set, problem.ids, problem.id_position
        p_full, ft = outcome.p, outcome.ft
        wp = np.array([ws.position[i] for i in ids if i in ws.position], dtype=np.int64)
        pw = np.array([p_full[idpos[i]] for i in ids if i in ws.position])
        twist = (problem.torque * problem.structure.unit_torque_twist
                 + (ws.twist_columns[wp] @ pw if wp.size else 0.0) + problem.modes.twist @ outcome.alpha)
        fw = np.array([ft[idpos[i]] for i in ids if i in ws.position])
        twist = level.add_slip_twist(twist, wp, fw)
        torque = float(outcome.alpha[-1]) if problem.torque_unknown else problem.torque
        return LevelSolution(p_full, ft, outcome.alpha, outcome.u, outcome.gap, ids, float(twist),
                             frozenset(act), torque, outcome.row_compliance)

    def _hertz_loop(self, problem: _LevelProblem, act: set[PairId],
                    level: Level) -> tuple[_ActiveSetOutcome, set[PairId]]:
        """PDAS solves with the Hertz secants of the balls and the flank layer's compliances
        (``LayerEdges``: each pair's share of the overlap integral) updated to convergence."""
        pb = self.ball_loads
        if pb is None:
            pb = np.full(problem.ball_index.size, 1.0)
        layer = problem.rows["tooth"].layer if "tooth" in problem.rows else None
        s_rows = problem.row_compliance.copy()
        ti = problem.tooth_index
        if layer is not None and self.layer_state is not None and self.layer_state[0] is layer:
            s_rows[ti] = self.layer_state[1]
        shares = LayerIteration(layer, ti) if layer is not None else None
        for _ in range(40):
            s_ball = self.ball_compliance * np.maximum(pb, 1e-3) ** (-1.0 / 3.0)
            outcome = self._pdas(problem, act, s_ball, level, s_rows)
            act = {problem.ids[j] for j in np.flatnonzero(outcome.p > 0)}
            pb_new = outcome.p[problem.ball_index]
            on = pb_new > 0        # the secant of an open ball does not matter
            change = (np.max(np.abs(pb_new - pb)[on]) if on.any() else 0.0) / max(
                1e-9, np.max(np.abs(pb_new)))
            pb = np.where(pb_new > 0, pb_new, pb)
            layer_residual, s_solved = 0.0, s_rows
            if shares is not None:
                s_rows, layer_residual = shares.step(outcome.p, outcome.gap, s_rows)
            if not outcome.converged:
                raise ContactFailure(f"active-set iteration did not converge in "
                                     f"{self.settings.max_iter} iterations at {problem.label}")
            if change < 1e-3 and layer_residual < self.settings.tol_gap:
                break
        else:
            raise ContactFailure("Hertz secant iteration on ball loads (and flank-layer shares) "
                                 "did not converge")
        self.ball_loads = pb
        if layer is not None:     # the updated shares warm-start the next level
            self.layer_state = (layer, s_rows[ti].copy())
            s_rows = s_solved
        outcome = replace(outcome, row_compliance=s_rows)   # what it was solved with
        if outcome.u is None:
            outcome = replace(outcome, u=self._displacement(problem, outcome.positions, outcome.p_active,
                                                            outcome.alpha))
        return outcome, act

    # ---------------------------------------------------------------- PDAS
    def _pdas(self, problem: _LevelProblem, act: set[PairId], s_ball: np.ndarray,
              level: Level, row_compliance: np.ndarray) -> _ActiveSetOutcome:
        """Primal-dual active set on the dense dual problem; see the module docstring."""
        ids = problem.ids
        sdiag = row_compliance.copy()
        sdiag[problem.ball_index] = s_ball
        Guq = problem.G @ problem.structure.unit_torque_u_watch
        A = set(act)
        # gaps at the current point of the step (a ratio-test step moves it; see _cut_back)
        gap_at = problem.free_gap.copy()
        loaded = bool(np.any(np.abs(problem.torque * problem.modes.load) > 1e-12))
        for it in range(self.settings.max_iter):
            self.iterations += 1
            self.enter(problem.structure, problem.rows, sorted(A - set(self.working_set.position)))
            self._hold_loaded_modes(problem, A)
            block = self._active_block(problem, A, sdiag, Guq)
            pA, p_full, ft_full, alpha, u, Gu = self._solve_block(problem, block, level, Guq)
            gap = problem.g0 + Gu + sdiag * p_full
            neg = [block.pairs[k] for k in np.flatnonzero(pA < 0)]
            viol = np.flatnonzero(gap < -self.settings.tol_gap)
            viol = viol[np.argsort(gap[viol])]
            viol = [ids[j] for j in viol if ids[j] not in A]
            # limited addition: the most violated few first (full switching cycles when
            # a near-mechanism makes one iterate overshoot)
            viol = viol[:max(self.settings.add_min, int(self.settings.add_frac * len(viol)))]
            if not neg and not viol:
                return _ActiveSetOutcome(np.maximum(p_full, 0.0), ft_full, alpha, u, gap, True,
                                         block.positions, pA)
            if loaded:
                cut = self._cut_back(problem, gap_at, gap)
                if cut is not None:      # overshoot: step to the first closing pair(s)
                    gap_at, closing = cut
                    A.update(closing)
                    continue
            if it > 25 and neg:          # anti-cycling: one change at a time
                neg = [block.pairs[int(np.argmin(pA))]]
            A.difference_update(neg)
            A.update(viol)
        return _ActiveSetOutcome(p_full, ft_full, alpha, u, gap, False, block.positions, pA)

    def _cut_back(self, problem: _LevelProblem, gap_at: np.ndarray,
                  gap: np.ndarray) -> tuple[np.ndarray, list[PairId]] | None:
        """Ratio test of an overshooting iterate (primal active-set step).

        The gaps are linear along the path from the current point (``gap_at``) to the
        iterate (``gap``).  If a pair open at the current point is penetrated by more than
        ``max_overshoot`` at the iterate, the step is cut back to t*, where the first open
        pair closes; returns the gaps at t* and the pairs closing there (to 1e-9 of t*).
        None if the iterate does not overshoot (or nothing closes along the step)."""
        tol = self.settings.tol_gap
        opened = gap_at > -tol
        if not opened.any() or -gap[opened].min() <= self.settings.max_overshoot:
            return None
        closing = np.flatnonzero(opened & (gap < -tol))
        t = np.maximum(gap_at[closing], 0.0) / (gap_at[closing] - gap[closing])
        tstar = float(t.min())
        first = closing[t <= tstar * (1.0 + 1e-9) + 1e-15]
        return gap_at + tstar * (gap - gap_at), [problem.ids[j] for j in first]

    def _hold_loaded_modes(self, problem: _LevelProblem, A: set[PairId]):
        """A loaded rigid mode with nothing holding it: add the first pair it closes."""
        position = self.working_set.position
        rows = [problem.id_position[i] for i in sorted(A, key=lambda i: position[i])]
        GR, load_per_torque = problem.mode_gap_rates, problem.modes.load
        for j in range(GR.shape[1]):
            load = problem.torque * load_per_torque[j]
            if abs(load) < 1e-12:
                continue
            held = np.abs(GR[rows, j]).max() if rows else 0.0
            if held > 1e-12:
                continue
            rate = GR[:, j] * np.sign(load)
            closing = np.flatnonzero(rate < -1e-12)
            if closing.size == 0:
                raise ContactFailure(f"rigid mode {problem.mode_names[j]} is loaded but no "
                                     "contact pair can hold it")
            need = problem.free_gap[closing] / (-rate[closing])
            jbest = closing[np.argmin(need)]
            A.add(problem.ids[jbest])
            self.enter(problem.structure, problem.rows, [problem.ids[jbest]])

    def _active_block(self, problem: _LevelProblem, A: set[PairId], sdiag: np.ndarray,
                      Guq: np.ndarray) -> ActiveBlock:
        """The blocks of the dual system on the active set A (``sdiag``: ball secants,
        ``Guq``: G K^-1 f per unit torque)."""
        ws = self.working_set
        Al = sorted(A, key=lambda i: ws.position[i])
        wp = np.array([ws.position[i] for i in Al], dtype=np.int64)
        rows = np.array([problem.id_position[i] for i in Al], dtype=np.int64)
        C = ws.compliance.take(wp, axis=0).take(wp, axis=1)   # (symmetric: ``WorkingSet``)
        C[np.diag_indices_from(C)] += sdiag[rows]
        T = problem.torque
        return ActiveBlock(
            torque=T, pairs=Al, positions=wp, rows=rows, compliance=C,
            mode_rows=problem.mode_gap_rates[rows],
            scale=np.abs(np.diag(C)).max() if len(Al) else 1.0,
            gap_rhs=-(problem.g0[rows] + T * Guq[rows]),
            mode_rhs=-T * problem.modes.load + problem.mode_target,
            n_pairs=len(problem.ids))

    def _solve_block(self, problem: _LevelProblem, block: ActiveBlock, level: Level, Guq: np.ndarray):
        """Solve the KKT system of an active set: (p_A, p, f_t, alpha, u_watch, G u).

        Without friction u is not formed (None): G u comes from the projected columns, and
        the Hertz loop forms u once from its last outcome.  With friction the tangential
        forces add their own columns to u, so u is formed and G applied to it."""
        system = level.kkt(block)
        nA, nS = len(block.pairs), system.n_tangential
        M = system.matrix
        M[nA + nS:, nA + nS:] = problem.mode_block     # (``_control``)
        if isinstance(level, FrictionlessLevel):
            sol = solve_frictionless_kkt(M, system.rhs, nA, self._factor(block))
        else:
            sol = solve_kkt(M, system.rhs)
        pA, alpha = sol[:nA], sol[nA + nS:]
        p_full = np.zeros(block.n_pairs)
        p_full[block.rows] = pA
        if isinstance(level, FrictionlessLevel):
            Gu = (problem.torque * Guq + problem.projected.combine(self.working_set, block.positions, pA)
                  + problem.mode_gap_rates @ alpha)
            return pA, p_full, np.zeros(block.n_pairs), alpha, None, Gu
        u = self._displacement(problem, block.positions, pA, alpha)
        u, ft_full = level.tangential(system, sol, block, u)
        return pA, p_full, ft_full, alpha, u, problem.G @ u

    def _displacement(self, problem: _LevelProblem, positions: np.ndarray, p_active: np.ndarray,
                      alpha: np.ndarray) -> np.ndarray:
        """u on the watch dofs from the torque, the active pairs' forces and the modes."""
        return (problem.torque * problem.structure.unit_torque_u_watch
                + self.working_set.store.combine(positions, p_active) + problem.modes.watch @ alpha)


    def _factor(self, block: ActiveBlock) -> Callable[[np.ndarray], Solve]:
        """C -> C^-1 of the block's C, kept across blocks that change only part of its diagonal."""
        return lambda C: self.active_factor.solver(C, block.positions, np.diag(block.compliance),
                                                   self.working_set)


def _same_rows(A: sp.csr_matrix, B: sp.csr_matrix) -> bool:
    """Whether two stacked row operators are the same numbers (so are their projections)."""
    return (A.shape == B.shape and A.nnz == B.nnz and np.array_equal(A.indptr, B.indptr)
            and np.array_equal(A.indices, B.indices) and np.array_equal(A.data, B.data))
