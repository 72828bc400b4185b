"""``LostMotionModel``: one design's FE model, assembled from its pieces.

The model holds the factorised bodies and their watch vector (``Structure``), the contact
rows by kind (``contact_rows``), the free rigid modes of the current stage, and the contact
solver's state (``ContactSolver``: working set, flank law, warm starts).  The test itself,
which mounts the wave generator and runs the torque cycle on a model, is ``cycle``.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, fields, replace

import numpy as np

from hdwf.drive.geometry import DriveGeometry
from hdwf.drive.mesh import BodyMesh, DriveMesh
from hdwf.fe.bodies import Body, Material, make_body, make_cs_body
from hdwf.fe.changes import ModelChanges
from hdwf.fe.contact_rows import Rows, stack_rows
from hdwf.fe.friction import flank_law
from hdwf.fe.hertz import ball_compliance_coeff
from hdwf.fe.node_columns import PATTERN_BODIES, NodeColumns
from hdwf.fe.solver import TOL_GAP, ContactFailure, ContactSolver, LevelSolution, SolverSettings, Twist
from hdwf.fe.structure import ModeName, Structure
from hdwf.fe.working_set import WorkingSet


ZONE_DEG = 35.0   # half width (deg) of the tooth zones about the major axes solved by default
LEVEL_CUTBACKS = 2   # a load level that does not converge is reached in up to 2 halvings of its step
# ... and the deepest of them, if it still fails, is tried once more with this many times the
# active-set iterations: an active set that fills slowly converges, one that cycles fails again
LAST_TRY_ITER_FACTOR = 5
# with a preload (``DriveGeometry.preloaded``), an active-set iterate that swings a loaded free mode so
# far that a pair open before is penetrated by more than this (units of the module m: a quarter
# of it, beyond the range the linearised tooth rows stand for) is cut back to the first closing
# pair (``solver``)
MAX_OVERSHOOT_M = 0.25


def _in_engagement_zones(bm: BodyMesh, nodes: np.ndarray, zone_deg: float) -> np.ndarray:
    """The ``nodes`` within ``zone_deg`` of either major axis (where the teeth engage)."""
    th = np.arctan2(bm.mesh.p[1, nodes], bm.mesh.p[0, nodes])
    dth = np.abs(np.angle(np.exp(2j * th))) / 2   # distance to nearest major axis
    return nodes[dth < math.radians(zone_deg)]


def _watch_nodes(bms: dict[str, BodyMesh], zone_deg: float) -> dict[str, np.ndarray]:
    """Every contact node of every body (teeth only in the engagement zones)."""
    return {
        "fs": np.concatenate([bms["fs"].node_sets["fs_bore"],
                              _in_engagement_zones(bms["fs"], bms["fs"].node_sets["fs_teeth"],
                                                   zone_deg)]),
        "cs": _in_engagement_zones(bms["cs"], bms["cs"].node_sets["cs_teeth"], zone_deg),
        "ir": np.concatenate([bms["ir"].node_sets["ir_bore"], bms["ir"].node_sets["ir_race"]]),
        "or": np.concatenate([bms["or"].node_sets["or_race"], bms["or"].node_sets["or_outer"]]),
    }


def with_flank_layer(geom: DriveGeometry, changes: ModelChanges) -> DriveGeometry:
    """``geom`` carrying the flank layer of ``changes`` and how it is solved; ``geom`` as it is
    when they have none."""
    if changes.flank_layer_m == 0:
        return geom
    return replace(geom, flank_layer_um_per_MPa=changes.layer_um_per_MPa(geom.module, geom.E),
                   flank_layer_fs_pass_only=changes.flank_layer_fs_pass_only)


@dataclass
class SharedBodies:
    """Bodies assembled and factorised once for several models of one design.

    A preload's allowance thickens the FS teeth and nothing else, so the variants of a design
    with different allowances have the same CS and bearing rings (``hdwf.drive.mesh.share_bodies``
    hands them the same body meshes).  A model given this object takes each body built from the
    same body-mesh object, steel, symmetry and watched zones by an earlier model, with the
    responses its nodes have had (``NodeColumns``: exact columns of K^-1), instead of building
    its own; the CS only when it is clamped at its own size (no housing, no temperature change).
    """

    # (body, E, nu, half, zone) -> (the body mesh it was built from, the body, its node responses)
    built: dict = field(default_factory=dict)

    def take(self, name: str, bm: BodyMesh, key: tuple) -> tuple[Body, NodeColumns | None] | None:
        """A copy of the body built from ``bm`` under ``key`` (its watch numbering its own), or None."""
        hit = self.built.get((name, *key))
        if hit is None or hit[0] is not bm:
            return None
        return copy.copy(hit[1]), hit[2]

    def keep(self, name: str, bm: BodyMesh, key: tuple, body: Body, columns: NodeColumns | None) -> None:
        self.built[(name, *key)] = (bm, body, columns)


class LostMotionModel:
    """Holds the factorised bodies, the contact rows and the contact solver's state.

    ``geom``, ``mesh``, ``E``, ``max_iter``, ``tol_gap`` and ``changes`` are those of
    ``solve_lost_motion``; ``zone_deg`` is the half width (deg) of the tooth engagement zones
    about the major axis whose nodes are watched, ``n_bins`` the number of OR / FS fit bins
    over the circle; ``shared`` the bodies it may take from earlier models (``SharedBodies``).
    """

    def __init__(self, geom: DriveGeometry, mesh: DriveMesh, E: float | None = None,
                 max_iter: int = 200, tol_gap: float = TOL_GAP, zone_deg: float = ZONE_DEG,
                 n_bins: int = 360, changes: ModelChanges | None = None,
                 shared: SharedBodies | None = None):
        self.changes = ModelChanges() if changes is None else changes
        self._plain_geometry = geom
        self.geometry = with_flank_layer(geom, self.changes)
        self.material = Material(geom.E if E is None else E, geom.nu)
        self.n_bins = n_bins
        self.half = (mesh.symmetry == "half"
                     or float(mesh.sizes.get("symmetry_half", 0.0)) == 1.0)
        body_meshes = dict(mesh.bodies)
        watch = _watch_nodes(body_meshes, zone_deg)
        self._cs_mesh, self._cs_watch = body_meshes["cs"], watch["cs"]
        self.factorize_s = 0.0
        bodies: dict[str, Body] = {}
        key = (self.material.E, self.material.nu, self.half, zone_deg)
        plain_cs = math.isinf(self.changes.cs_rim_stiffness_N_mm2) and self.changes.cs_scale == 1.0
        taken: dict[str, NodeColumns | None] = {}
        for name in ("fs", "cs", "ir", "or"):
            hit = shared.take(name, body_meshes[name], key) if shared and (name != "cs" or plain_cs) else None
            if hit is not None:
                bodies[name], taken[name] = hit
                continue
            if name == "cs":
                body, seconds = self._build_cs(self.changes)
            else:
                body, seconds = make_body(name, body_meshes[name], self.material, watch[name],
                                          half=self.half)
            self.factorize_s += seconds
            bodies[name] = body
        self.structure = Structure(bodies, self.half, geom.r_fs_root,
                                   {"fs": geom.z_fs, "cs": geom.z_cs})
        for name, columns in taken.items():
            if columns is not None:
                self.structure.adopt_node_columns(name, columns)
        if shared is not None:
            for name in set(bodies) - set(taken) - ({"cs"} if not plain_cs else set()):
                columns = self.structure.node_columns(name) if name in PATTERN_BODIES else None
                shared.keep(name, body_meshes[name], key, bodies[name], columns)
        self.rows: dict[str, Rows] = {}
        self.mode_list: list[ModeName] = []     # free rigid modes of the current stage
        nwatch = self.structure.nwatch
        # the cut-back only with a preload: without one the FS crosses its whole backlash (80 um
        # on HD 42 set 8 at the paper's density) in one iterate, and cut back there it stalls
        overshoot = MAX_OVERSHOOT_M * geom.module if geom.preloaded else np.inf
        self.solver = ContactSolver(SolverSettings(max_iter, tol_gap, max_overshoot=overshoot),
                                    ball_compliance_coeff(geom, self.material.E),
                                    WorkingSet(nwatch),
                                    flank_law(self.changes.flank_friction, nwatch))

    @property
    def bodies(self) -> dict[str, Body]:
        return self.structure.bodies

    @property
    def nwatch(self) -> int:
        return self.structure.nwatch

    @property
    def n_dofs(self) -> int:
        return self.structure.n_dofs

    @property
    def iterations(self) -> int:
        """Active-set iterations so far."""
        return self.solver.iterations

    def _build_cs(self, changes: ModelChanges) -> tuple[Body, float]:
        return make_cs_body(self._cs_mesh, self._cs_watch, self.material, self.half, changes)

    def fork(self) -> "LostMotionModel":
        """A copy that shares the factorised bodies and copies the mutable contact state."""
        new = copy.copy(self)
        new.rows = dict(self.rows)
        new.mode_list = list(self.mode_list)
        new.solver = self.solver.copy()
        return new

    def apply_tooth_stage_changes(self, changes: ModelChanges):
        """Switch the tooth-stage changes (friction, CS scale and support) on a model whose
        wave generator is mounted: none of them touches the bodies or contacts of that stage
        (the CS has no contact before the teeth), so it is reused as it is."""
        pairs = self.solver.working_set.pairs
        if any(k == "tooth" for k, _ in pairs):
            raise RuntimeError("apply_tooth_stage_changes: the teeth are already engaged")
        old = self.changes
        handled = {"flank_friction", "cs_rim_stiffness_N_mm2", "cs_scale", "flank_layer_m"}
        other = [f.name for f in fields(ModelChanges) if f.name not in handled
                 and getattr(changes, f.name) != getattr(ModelChanges(), f.name)]
        if other:    # a new tooth-stage change must be applied here too (adding-an-effect.md)
            raise NotImplementedError(f"apply_tooth_stage_changes does not apply {other}")
        if (changes.cs_scale, changes.cs_rim_stiffness_N_mm2) != (old.cs_scale,
                                                                   old.cs_rim_stiffness_N_mm2):
            self._switch_cs(changes, old)
        self.solver.friction = flank_law(changes.flank_friction, self.nwatch,
                                         self.solver.friction, len(pairs))
        self.geometry = with_flank_layer(self._plain_geometry, changes)   # the tooth rows come after this
        self.changes = changes

    def _switch_cs(self, changes: ModelChanges, old: ModelChanges):
        """The CS of ``changes`` in place of that of ``old`` (same watch positions)."""
        prev = self.bodies["cs"]
        if (changes.cs_rim_stiffness_N_mm2 == old.cs_rim_stiffness_N_mm2
                and not math.isfinite(old.cs_rim_stiffness_N_mm2) and not prev.modes):
            # a clamped CS only scaled (thermal strain): same stiffness, same factorisation
            body = prev.scaled(changes.cs_scale / old.cs_scale)
        else:
            body, seconds = self._build_cs(changes)
            body.watch_offset, body.watch_index = prev.watch_offset, prev.watch_index
            self.factorize_s += seconds
        self.structure = self.structure.with_body("cs", body)

    def replace_rows(self, kind: str, rows: Rows):
        """New linearisation of one kind of rows (same count): refresh its columns."""
        self.rows[kind] = rows
        self.solver.refresh(self.structure, self.rows, kind)

    def solve_level(self, torque: float | Twist, active: frozenset | None) -> LevelSolution:
        """The contact solution at ``torque`` (N mm) or a prescribed ``Twist``, warm-started from ``active``."""
        return self.solver.solve_level(self.structure, self.rows, self.mode_list, torque, active)

    def solve_level_stepped(self, torque: float | Twist, active: frozenset | None, from_torque: float | Twist,
                            cutbacks: int = LEVEL_CUTBACKS) -> LevelSolution:
        """``solve_level``; if it fails (an active set that cycles), the load halfway from
        ``from_torque`` (the last level's: a torque, or a prescribed ``Twist``) is solved first and
        this one from there, as an FE code cuts back a load step, at most ``cutbacks`` halvings
        deep; the deepest is tried once more with ``LAST_TRY_ITER_FACTOR`` times the active-set
        iterations.  A failed solve leaves the warm start and the friction state of the last level
        (it commits them only when it converges), so the retry starts where the failed one did."""
        try:
            return self.solve_level(torque, active)
        except ContactFailure:
            if cutbacks == 0:
                return self._solve_level_longer(torque, active)
            mid = (Twist(0.5 * (from_torque.rad + torque.rad)) if isinstance(torque, Twist)
                   else 0.5 * (from_torque + torque))
            half = self.solve_level_stepped(mid, active, from_torque, cutbacks - 1)
            return self.solve_level_stepped(torque, half.active, mid, cutbacks - 1)

    def _solve_level_longer(self, torque: float | Twist, active: frozenset | None) -> LevelSolution:
        """``solve_level`` with ``LAST_TRY_ITER_FACTOR`` times the active-set iterations; its
        failure (naming the larger limit) is raised as it is."""
        settings = self.solver.settings
        self.solver.settings = replace(settings, max_iter=LAST_TRY_ITER_FACTOR * settings.max_iter)
        try:
            return self.solve_level(torque, active)
        finally:
            self.solver.settings = settings

    def full_displacements(self, solution: LevelSolution, torque: float) -> dict[str, np.ndarray]:
        """Displacement (2, nnodes) of every body at a solved level, u = K^-1 (f + G^T p) + R alpha
        (the same superposition the twist is read from); one back-substitution per body."""
        forces = stack_rows(self.rows).G.T @ solution.normal_force
        forces = self.solver.friction.add_slip_forces(forces, self.rows, solution.tangential_force)
        return self.structure.full_displacements(forces, torque, self.mode_list,
                                                 solution.mode_amplitude)
