"""The FE model with effects switched on, at measured specimens: variants, tables, synthesis.

A *variant* is the baseline FE model with some effects switched on at given values,
``{effect: {param: value}}``; its key is a canonical string (``"baseline"``,
``"thermal:delta_T_K=20"``, ``"fs_cup_torsion:K_Nm_per_rad=60000+thermal:delta_T_K=20"``).

Reuse between candidates (what makes a campaign affordable):

* one mesh per specimen, built once and shared by every variant of that specimen;
* one assembly and factorisation of the bodies and one wave-generator stage per specimen:
  every effect acts only once the teeth engage (``hdwf.fe.solve_lost_motion_variants``),
  so each variant costs only its torque sequence (and the housing a new CS factorisation);
* variants that differ only in effects acting in series at the output (``Effect.series``:
  cup torsion, Oldham play) share one contact solve: their twist is the solved rim twist
  plus the series element's, exactly;
* the calibration of every candidate reads the per-specimen tables (each parameter's grid),
  so it costs no solve at all (``hdwf.validation.diagnosis``).
"""

from __future__ import annotations

import math
import multiprocessing as mp
from dataclasses import dataclass
import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd

from hdwf import PARAMETER_COLUMNS
from hdwf.validation.effects import get as get_effect
from hdwf.validation.effects import model_changes, registry
from hdwf.fe import ModelChanges, series_output_twist
from hdwf.drive.geometry import ARCMIN

BASELINE = "baseline"
_BLAS_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
TABLE_COLUMNS = ["specimen_id", "variant", "step", "torque_Nm", "twist_arcmin", "status"]


def variant_key(effects: dict[str, dict[str, float]]) -> str:
    if not effects:
        return BASELINE
    parts = []
    for name in sorted(effects):
        for p, v in sorted(effects[name].items()):
            parts.append(f"{name}:{p}={float(v):.10g}")
    return "+".join(parts)


def candidate_names(fixed: dict | None = None) -> list[str]:
    """Every registered effect that is not already part of the campaign's model."""
    return [n for n in registry() if n not in (fixed or {})]


def plan_variants(fixed: dict[str, dict[str, float]] | None = None,
                  candidates: list[str] | None = None) -> list[dict]:
    """The campaign model (baseline + ``fixed`` effects) and, for every candidate effect,
    the model with that effect at each value of its parameter's grid (one parameter each)."""
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


def solve_variants(unit: str, params: dict[str, float], mesh, steps_per_ramp: int,
                   variants: list[dict], specimen_id: str) -> pd.DataFrame:
    """Solve one specimen for every variant (one contact solve per distinct FE part).

    A variant whose solve fails gets ``status = "failed: <reason>"`` and NaN twists."""
    from hdwf.fe import solve_lost_motion_variants
    from hdwf.drive.design import geometry_of

    geom = geometry_of(unit, params)
    changes = [model_changes(eff) for eff in variants]
    parts = list(dict.fromkeys(ch.fe_part() for ch in changes))   # distinct, in order
    solved = dict(zip(parts, solve_lost_motion_variants(geom, mesh, steps_per_ramp, parts)))
    frames = []
    for eff, ch in zip(variants, changes):
        fe_part = ch.fe_part()
        res = solved[fe_part]
        ok = res.status == "ok"
        if ok:
            tw = res.twist_arcmin + _series_shift_arcmin(res.torque_Nm, ch)
            step, torque = res.step, res.torque_Nm
        else:
            step = np.arange(4 * steps_per_ramp + 1)
            torque = np.full(step.size, np.nan)
            tw = np.full(step.size, np.nan)
        frames.append(pd.DataFrame({
            "specimen_id": specimen_id, "variant": variant_key(eff),
            "step": np.asarray(step, dtype="int64"), "torque_Nm": np.asarray(torque, float),
            "twist_arcmin": np.asarray(tw, float),
            "status": "ok" if ok else f"failed: {res.reason}"}))
    return pd.concat(frames, ignore_index=True)[TABLE_COLUMNS]


def _specimen_job(args):
    unit, params, settings, steps, variants, sid = args
    from hdwf.drive.design import mesh_design

    mesh = mesh_design(unit, params, settings)
    return solve_variants(unit, params, mesh, steps, variants, sid)


def solve_specimens(unit: str, specimens: pd.DataFrame, settings: dict, steps_per_ramp: int,
                    variants_of, jobs: int = 1) -> pd.DataFrame:
    """``solve_variants`` for every specimen row (``variants_of(specimen_id)`` gives its list),
    in ``jobs`` processes; rows in specimen order."""
    tasks = [(unit, {c: float(r[c]) for c in PARAMETER_COLUMNS}, settings, steps_per_ramp,
              variants_of(r["specimen_id"]), r["specimen_id"]) for _, r in specimens.iterrows()]
    if jobs <= 1 or len(tasks) <= 1:
        out = [_specimen_job(t) for t in tasks]
    else:
        # fresh interpreters with one BLAS thread each: the dense solves are small, and
        # 2 processes x 2 BLAS threads on 2 cores only fight
        saved = {k: os.environ.get(k) for k in _BLAS_VARS}
        os.environ.update({k: "1" for k in _BLAS_VARS})
        try:
            with ProcessPoolExecutor(max_workers=jobs, mp_context=mp.get_context("spawn")) as ex:
                out = list(ex.map(_specimen_job, tasks))
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
    return pd.concat(out, ignore_index=True)


def specimen_solver(unit: str, specimens: pd.DataFrame, settings: dict, steps_per_ramp: int, jobs: int = 1):
    """``solve(variants)``: the same ``variants`` solved for every specimen (``solve_specimens``)."""
    def solve(variants: list[dict]) -> pd.DataFrame:
        return solve_specimens(unit, specimens, settings, steps_per_ramp, lambda _: variants, jobs)
    return solve


# ------------------------------------------------------------------ synthetic measurements

def mean_lost_motion(table: pd.DataFrame, fixed: dict | None = None) -> float:
    """Mean over specimens of the twist range of the campaign model's curves (arcmin): the
    signal that noise levels are quoted against."""
    base = table[table["variant"] == variant_key(fixed or {})]
    return float(base.groupby("specimen_id")["twist_arcmin"].agg(lambda t: t.max() - t.min()).mean())


def synth_designs(unit: str, n: int, seed: int,
                  ranges: dict[str, tuple[float, float]] | None = None) -> pd.DataFrame:
    """``n`` specimens by Latin hypercube (seeded) over the paper's Table 3 ranges, or over
    ``ranges`` ({column: (low, high)}, e.g. ``{"rFS_mm": (0, 0.002)}``) where given: a batch
    like the one on the bench rather than the paper's design space (docs/validation.md)."""
    from scipy.stats import qmc

    from hdwf import PARAMETERS

    bounds = design_ranges(unit, ranges)
    lo = np.array([bounds[c][0] for c in PARAMETER_COLUMNS])
    hi = np.array([bounds[c][1] for c in PARAMETER_COLUMNS])
    u = qmc.LatinHypercube(d=len(PARAMETERS), seed=seed).random(n)
    x = lo + u * (hi - lo)      # qmc.scale refuses a zero-width range; a fixed value is allowed
    df = pd.DataFrame(x, columns=list(PARAMETER_COLUMNS))
    df.insert(0, "unit", unit)
    df.insert(0, "specimen_id", [f"{unit}-s{i + 1:03d}" for i in range(n)])
    return df


def design_ranges(unit: str, ranges: dict[str, tuple[float, float]] | None = None) -> dict[str, tuple[float, float]]:
    """The sampling range of every parameter column: Table 3's, replaced by ``ranges`` where
    given. A range must lie inside what the model supports (``measurements.supported_bounds``)."""
    from hdwf.validation.measurements import TABLE3_BOUNDS, supported_bounds

    if unit not in TABLE3_BOUNDS:
        raise ValueError(f"unknown drive {unit!r}; known: {', '.join(TABLE3_BOUNDS)}")
    out = {f"{p}_mm": (float(lo), float(hi)) for p, (lo, hi) in TABLE3_BOUNDS[unit].items()}
    supported = {f"{p}_mm": b for p, b in supported_bounds(unit).items()}
    for col, (lo, hi) in (ranges or {}).items():
        if col not in out:
            raise ValueError(f"unknown parameter {col!r} in a design range; known: {', '.join(out)}")
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise ValueError(f"design range of {col} must be two finite numbers, got {lo!r}:{hi!r}")
        if lo > hi:
            raise ValueError(f"design range of {col} must be low <= high, got {lo!r}:{hi!r}")
        s_lo, s_hi = supported[col]
        if lo < s_lo or hi > s_hi:
            raise ValueError(f"design range {col} = {lo:g}:{hi:g} leaves what the {unit} model supports "
                             f"({s_lo:g}:{s_hi:g})")
        out[col] = (float(lo), float(hi))
    return out


def parse_range(text: str) -> tuple[str, float, float]:
    """``"rFS_mm=0:0.002"`` -> ``("rFS_mm", 0.0, 0.002)`` (the ``--range`` option)."""
    name, sep, rest = text.partition("=")
    low, sep2, high = rest.partition(":")
    try:
        if not (sep and sep2 and name.strip()):
            raise ValueError
        return name.strip(), float(low), float(high)
    except ValueError:
        raise ValueError(f"expected NAME=LOW:HIGH (e.g. rFS_mm=0:0.002), got {text!r}") from None


def format_ranges(ranges: dict[str, tuple[float, float]]) -> str:
    """``", rFS_mm 0..0.002, ..."``: the design ranges for a printed summary ("" for none)."""
    return "".join(f", {c} {lo:g}..{hi:g}" for c, (lo, hi) in ranges.items())


def synthesize(unit: str, n_designs: int, seed: int, noise_arcmin: float,
               effects: dict[str, dict[str, float]] | None, settings: dict,
               steps_per_ramp: int = 5, jobs: int = 1,
               ranges: dict[str, tuple[float, float]] | None = None) -> pd.DataFrame:
    """Measurements in the documented curve form from the FE model with ``effects`` on:
    the solved curve of each specimen plus Gaussian noise of ``noise_arcmin`` (seeded),
    with ``u_twist_arcmin`` = the noise level. A failed solve raises (no silent rows)."""
    if noise_arcmin < 0 or not math.isfinite(noise_arcmin):
        raise ValueError(f"noise_arcmin must be >= 0, got {noise_arcmin!r}")
    return add_noise(synth_curves(unit, n_designs, seed, effects, settings, steps_per_ramp, jobs, ranges),
                     noise_arcmin, seed)


def synth_curves(unit: str, n_designs: int, seed: int, effects: dict[str, dict[str, float]] | None,
                 settings: dict, steps_per_ramp: int = 5, jobs: int = 1,
                 ranges: dict[str, tuple[float, float]] | None = None) -> pd.DataFrame:
    """The noise-free curves ``synthesize`` starts from (one solve per specimen)."""
    specimens = synth_designs(unit, n_designs, seed, ranges)
    effects = effects or {}
    model_changes(effects)    # checks names, parameters and bounds before any solve
    table = specimen_solver(unit, specimens, settings, steps_per_ramp, jobs)([effects])
    bad = table[table["status"] != "ok"]
    if len(bad):
        raise RuntimeError(f"synthesis: the FE solve failed for specimen "
                           f"{bad['specimen_id'].iloc[0]}: {bad['status'].iloc[0]}")
    return specimens.merge(table.drop(columns=["variant", "status"]), on="specimen_id")


def add_noise(curves: pd.DataFrame, noise_arcmin: float, seed: int) -> pd.DataFrame:
    """Gaussian noise of ``noise_arcmin`` on every twist (``numpy`` generator seeded with ``seed``)."""
    rng = np.random.default_rng(seed)
    data = curves.copy()
    data["twist_arcmin"] = data["twist_arcmin"] + rng.normal(0.0, noise_arcmin, len(data))
    data["u_twist_arcmin"] = noise_arcmin
    return data[["specimen_id", "unit", *PARAMETER_COLUMNS, "step", "torque_Nm", "twist_arcmin",
                 "u_twist_arcmin"]]


# ------------------------------------------------------------------ campaigns (workflow stages)

@dataclass
class CampaignPlan:
    """A validation campaign from ``config.yaml`` (``validation: {NAME: ...}``), resolved."""
    name: str
    unit: str
    measurements: str
    fixed: dict            # effects switched on at given values
    calibrate_first: list  # effects switched on and calibrated before the search
    candidates: list       # effects the diagnosis tries
    rounds: int
    settings: dict         # mesh settings of its solves
    steps_per_ramp: int

    def table_variants(self) -> list[dict]:
        return plan_variants(self.fixed, self.candidates)


def campaign_plan(name: str, camp: dict, fe: dict) -> CampaignPlan:
    fixed, calib = {}, []
    for eff, params in camp.get("effects", {}).items():
        if any(v == "calibrate" for v in params.values()):
            calib.append(eff)
        else:
            fixed[eff] = {p: float(v) for p, v in params.items()}
    cands = camp.get("candidates", "all")
    cands = candidate_names(fixed) if cands == "all" else [c for c in cands if c not in fixed]
    cands = sorted(set(cands) | set(calib))
    mesh = camp.get("mesh", {})
    settings = {"elements_over_height": mesh.get("elements_over_height", fe["elements_over_height"]),
                "elements_over_thickness": mesh.get("elements_over_thickness", fe["elements_over_thickness"]),
                "refinement": mesh.get("refinement", fe["refinement"]),
                "symmetry": fe.get("symmetry", "full")}
    return CampaignPlan(name, camp["unit"], camp["measurements"], fixed, calib, cands,
                        int(camp.get("rounds", 2)), settings,
                        int(camp.get("steps_per_ramp", fe["steps_per_ramp"])))


def specimen_stage(unit: str, specimen: dict, settings: dict, steps_per_ramp: int, variants: list[dict],
                   out, provenance: dict) -> pd.DataFrame:
    """Mesh one specimen once and solve it for every variant (one campaign table)."""
    from hdwf.drive.design import mesh_design
    from hdwf.common.io import write_parquet

    sid = specimen["specimen_id"]
    params = {c: float(specimen[c]) for c in PARAMETER_COLUMNS}
    mesh = mesh_design(unit, params, settings)
    table = solve_variants(unit, params, mesh, steps_per_ramp, variants, sid)[TABLE_COLUMNS]
    write_parquet(table, out, provenance=provenance,
                  meta={"unit": unit, "specimen_id": sid, "mesh": settings})
    return table
