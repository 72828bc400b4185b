"""Model variants and their solves: the FE model with some effects switched on, per specimen.

A *variant* is the baseline FE model with some effects switched on at given values,
``{effect: {param: value}}``; its key is a canonical string (``"baseline"``,
``"thermal:delta_T_K=20"``, ``"fs_cup_torsion:K_Nm_per_rad=60000+thermal:delta_T_K=20"``).
A *table* holds the solved curves of a specimen's variants, one row per load step
(``TABLE_COLUMNS``).

Reuse between candidates (what makes a campaign affordable):

* one mesh per specimen, built once and shared by every variant of that specimen (a variant
  that reshapes the section, a preload, gets a mesh of its own, shared by its variants; the
  allowances of a specimen differ in the FS teeth only, so their outlines mesh only the FS
  anew and share the CS and bearing rings, assembled and factorised once: ``SharedBodies``);
* one assembly and factorisation of the bodies and one wave-generator stage per specimen:
  every effect acts only once the teeth engage (``hdwf.fe.solve_lost_motion_variants``),
  so each variant costs only its torque sequence (and the housing a new CS factorisation);
* variants that differ only in effects acting in series at the output (``Effect.series``:
  cup torsion, Oldham play) share one contact solve: their twist is the solved rim twist
  plus the series element's, exactly;
* the calibration of every candidate reads the per-specimen tables (each parameter's grid),
  so it costs no solve at all (``hdwf.validation.calibration``).

Specimens are solved one per process (``solve_specimens``), in fresh interpreters.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import sys
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Callable, Mapping

import numpy as np
import pyarrow as pa
from tqdm import tqdm

from hdwf import PARAMETER_COLUMNS
from hdwf.common.blas import BLAS_VARS
from hdwf.common.io import arrow_table
from hdwf.drive.design import MeshSettings, geometry_of
from hdwf.drive.geometry import ARCMIN, DriveGeometry
from hdwf.drive.mesh import share_bodies
from hdwf.fe import ModelChanges, series_output_twist, solve_lost_motion_variants
from hdwf.fe.model import SharedBodies
from hdwf.validation.effects import get as get_effect
from hdwf.validation.effects import model_changes, registry

if TYPE_CHECKING:   # a specimen's job (one specimen, an Arrow table out) starts without pandas
    import pandas as pd

BASELINE = "baseline"
TABLE_COLUMNS = ["specimen_id", "variant", "step", "torque_Nm", "twist_arcmin", "status", "ball_pressure_max_MPa",
                 "max_penetration_redetected_um"]
# ball_pressure_max_MPa: the most loaded wave-generator ball's raceway pressure at the mount (the
# same for every step of a variant), to hold a found effect against the bearing's rating;
# max_penetration_redetected_um: the solver's check from scratch at +-T, as the studies' rows keep it


@dataclass(frozen=True)
class SolveSetup:
    """How the specimens of one drive are solved.

    Attributes
    ----------
    unit : str
        The drive (``"hd42"`` or ``"hd120"``).
    mesh : Mapping
        Mesh settings (the fields of ``hdwf.drive.design.MeshSettings``).
    steps_per_ramp : int
        Load steps per ramp of the test 0 → +T → 0 → −T → 0 (4 × this + 1 points).
    jobs : int
        Processes, one specimen each.
    progress : bool
        Show a progress bar on stderr while solving (the CLI's commands do; rules log instead).
    """

    unit: str
    mesh: Mapping
    steps_per_ramp: int = 5
    jobs: int = 1
    progress: bool = False


def variant_key(effects: dict[str, dict[str, float]]) -> str:
    """The canonical key of a variant.

    Parameters
    ----------
    effects : dict
        ``{effect: {param: value}}``; empty for the baseline.

    Returns
    -------
    str
        ``"baseline"``, or ``effect:param=value`` parts (sorted, ``%.10g``) joined by ``+``.
    """
    if not effects:
        return BASELINE
    parts = []
    for name in sorted(effects):
        for p, v in sorted(effects[name].items()):
            parts.append(f"{name}:{p}={float(v):.10g}")
    return "+".join(parts)


def candidate_names(fixed: dict | None = None) -> list[str]:
    """Every registered effect that is not already part of the campaign's model, but those
    offered only by name (``Effect.named_only``).

    Parameters
    ----------
    fixed : dict, optional
        The effects switched on in the campaign's model, ``{effect: {param: value}}``.

    Returns
    -------
    list of str
        Effect names in registry order.
    """
    return [n for n, eff in registry().items() if n not in (fixed or {}) and not eff.named_only]


def plan_variants(fixed: dict[str, dict[str, float]] | None = None,
                  candidates: list[str] | None = None) -> list[dict]:
    """The variants of a campaign's tables.

    Parameters
    ----------
    fixed : dict, optional
        The effects switched on in the campaign's model.
    candidates : list of str, optional
        The effects to tabulate (default: ``candidate_names(fixed)``); one parameter each.

    Returns
    -------
    list of dict
        The campaign model (baseline + ``fixed``), then for every candidate the model with that
        effect at each value of its parameter's grid.
    """
    fixed = dict(fixed or {})
    candidates = candidate_names(fixed) if candidates is None else candidates
    plan = [fixed]
    for name in candidates:
        eff = get_effect(name)
        if len(eff.parameters) != 1:
            raise ValueError(f"effect {name!r}: calibration handles one-parameter effects only")
        p = eff.parameters[0]
        for v in p.grid():
            plan.append({**fixed, name: {p.name: v}})
    return plan


def _series_shift_arcmin(torque_Nm: np.ndarray, changes: ModelChanges) -> np.ndarray:
    """What the series elements add to a solved curve (relative to its first point)."""
    add = series_output_twist(np.zeros(len(torque_Nm)), np.asarray(torque_Nm) * 1000.0,
                              changes) / ARCMIN
    return add - add[0]


def solve_specimen(setup: SolveSetup, specimen: Mapping, variants: list[dict]) -> pa.Table:
    """Mesh one specimen and solve it for every variant (one contact solve per distinct FE part).

    Parameters
    ----------
    setup : SolveSetup
        Drive, mesh settings and load steps (``jobs`` is not used).
    specimen : Mapping
        ``specimen_id`` and the parameter columns ``d_mm`` … ``rCS_mm``.
    variants : list of dict
        The variants, ``{effect: {param: value}}`` each.

    Returns
    -------
    pyarrow.Table
        The specimen's table (``TABLE_COLUMNS``), variants in the given order. A variant whose
        solve fails gets ``status = "failed: <reason>"`` and no twists (null, NaN in pandas).
    """
    params = {c: float(specimen[c]) for c in PARAMETER_COLUMNS}
    settings = MeshSettings.from_mapping(setup.mesh)
    steps = setup.steps_per_ramp
    changes = [model_changes(eff) for eff in variants]
    parts = list(dict.fromkeys(ch.fe_part() for ch in changes))   # distinct, in order
    # one geometry and mesh per outline (a preload thickens the teeth), shared by its variants
    outlines: dict[tuple, list[ModelChanges]] = {}
    for part in parts:
        outlines.setdefault(tuple(sorted(part.geometry_part().items())), []).append(part)
    solved, first_preloaded, shared = {}, None, SharedBodies()
    for outline, group in outlines.items():
        geom = geometry_of(setup.unit, params, **dict(outline))
        if first_preloaded is not None and _fs_only_differs(geom, first_preloaded[0]):
            mesh = share_bodies(settings.mesh(geom, bodies=("fs",)), first_preloaded[1])
        else:
            mesh = settings.mesh(geom)
            if geom.interference_m > 0 and first_preloaded is None:
                first_preloaded = (geom, mesh)
        # only allowances share bodies (the bare outline's CS has no relief): keep none of its
        solved.update(zip(group, solve_lost_motion_variants(geom, mesh, steps, group,
                                                            shared if geom.interference_m > 0 else None)))
    frames = []
    for eff, ch in zip(variants, changes):
        res = solved[ch.fe_part()]
        ok = res.status == "ok"
        if ok:
            tw = res.twist_arcmin + _series_shift_arcmin(res.torque_Nm, ch)
            step, torque = res.step, res.torque_Nm
        else:
            step = np.arange(4 * steps + 1)
            torque = np.full(step.size, np.nan)
            tw = np.full(step.size, np.nan)
        n = len(step)
        frames.append(arrow_table(dict(zip(TABLE_COLUMNS, (
            [specimen["specimen_id"]] * n, [variant_key(eff)] * n, np.asarray(step, dtype="int64"),
            np.asarray(torque, float), np.asarray(tw, float), ["ok" if ok else f"failed: {res.reason}"] * n,
            np.full(n, float(res.max_ball_pressure_MPa) if ok else np.nan),
            np.full(n, float(res.max_penetration_redetected_um) if ok else np.nan))))))
    return pa.concat_tables(frames)


def _fs_only_differs(geom: DriveGeometry, other: DriveGeometry) -> bool:
    """Whether two outlines of a specimen differ in the FS flank allowance only (which thickens
    the FS teeth and nothing else: ``DriveGeometry.interference``)."""
    return replace(other, interference_m=geom.interference_m) == geom


def _specimen_job(task: tuple[SolveSetup, dict, list[dict]]) -> pa.Table:
    return solve_specimen(*task)


@contextmanager
def _one_blas_thread():
    """BLAS limited to one thread in the processes started inside the block."""
    saved = {k: os.environ.get(k) for k in BLAS_VARS}
    os.environ.update({k: "1" for k in BLAS_VARS})
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def solve_specimens(setup: SolveSetup, specimens: pd.DataFrame,
                    variants_of: Callable[[str], list[dict]]) -> pd.DataFrame:
    """``solve_specimen`` for every specimen row, in ``setup.jobs`` processes.

    Parameters
    ----------
    setup : SolveSetup
        Drive, mesh settings, load steps and processes.
    specimens : pandas.DataFrame
        One row per specimen: ``specimen_id`` and the parameter columns.
    variants_of : callable
        ``variants_of(specimen_id)`` gives that specimen's list of variants.

    Returns
    -------
    pandas.DataFrame
        The specimens' tables, concatenated in specimen order.
    """
    tasks = [(setup, {"specimen_id": r["specimen_id"], **{c: float(r[c]) for c in PARAMETER_COLUMNS}},
              variants_of(r["specimen_id"])) for _, r in specimens.iterrows()]
    n_solves = sum(len(t[2]) for t in tasks)
    with tqdm(total=len(tasks), desc=f"{setup.unit}: {len(tasks)} specimens, {n_solves} solves", unit="specimen",
              disable=not setup.progress, file=sys.stderr) as bar:
        if setup.jobs <= 1 or len(tasks) <= 1:
            out = []
            for t in tasks:
                out.append(_specimen_job(t))
                bar.update(1)
        else:
            # fresh interpreters with one BLAS thread each: the dense solves are small, and
            # 2 processes x 2 BLAS threads on 2 cores only fight
            with _one_blas_thread(), ProcessPoolExecutor(max_workers=setup.jobs,
                                                         mp_context=mp.get_context("spawn")) as ex:
                out = []
                for table in ex.map(_specimen_job, tasks):
                    out.append(table)
                    bar.update(1)
    return pa.concat_tables(out).to_pandas()


def specimen_solver(setup: SolveSetup, specimens: pd.DataFrame) -> Callable[[list[dict]], pd.DataFrame]:
    """The same variants solved for every specimen (``setup`` and ``specimens`` as for
    ``solve_specimens``).

    Returns
    -------
    callable
        ``solve(variants)``: the tables of every specimen for those variants (``solve_specimens``).
    """
    def solve(variants: list[dict]) -> pd.DataFrame:
        return solve_specimens(setup, specimens, lambda _: variants)
    return solve


def mean_lost_motion(table: pd.DataFrame, fixed: dict | None = None) -> float:
    """The signal that noise levels are quoted against.

    Parameters
    ----------
    table : pandas.DataFrame
        Solved tables of one or more specimens (``TABLE_COLUMNS``).
    fixed : dict, optional
        The campaign model's effects (default: the baseline).

    Returns
    -------
    float
        Mean over specimens of the twist range of the campaign model's curves (arcmin).
    """
    base = table[table["variant"] == variant_key(fixed or {})]
    return float(base.groupby("specimen_id")["twist_arcmin"].agg(lambda t: t.max() - t.min()).mean())
