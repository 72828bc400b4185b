"""Stages of the validation campaigns (rules in ``workflow/rules/validation.smk``): a campaign's
plan from the config, the diagnosis, the ladder and the figures.  The per-specimen tables (a job
each) are ``hdwf.stages.validation_specimen``.

Each stage reads its inputs, calls ``hdwf.validation`` and writes what its rule promises.
"""

from __future__ import annotations

# The figures (matplotlib) and the diagnosis (statsmodels) are imported by the stages that use
# them: the Snakefile imports this module to plan the campaigns, and the ladder needs neither.

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from hdwf.common.io import read_json, write_json, write_parquet
from hdwf.common.jsonsafe import json_safe
from hdwf.validation.ladder import ladder_variants, solve_ladder
from hdwf.validation.measurements import MeasurementError, load_measurements, schedule_problems
from hdwf.validation.recovery import recovery
from hdwf.validation.variants import SolveSetup, candidate_names, plan_variants, specimen_solver

if TYPE_CHECKING:
    from hdwf.validation.diagnosis import Search


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
    about: str = ""        # what the measurements are, for the report
    hidden_effects: dict = field(default_factory=dict)   # synthetic data: {effect: {param: value}} made with
    data_mesh: dict = field(default_factory=dict)        # synthetic data made on another mesh: its settings

    def table_variants(self) -> list[dict]:
        """The variants every specimen's table holds (``hdwf.validation.variants.plan_variants``)."""
        return plan_variants(self.fixed, self.candidates)

    def search(self) -> Search:
        """What its diagnosis searches."""
        from hdwf.validation.diagnosis import Search
        return Search(self.fixed, self.calibrate_first, self.candidates, self.rounds)

    def solve_setup(self, jobs: int = 1) -> SolveSetup:
        """How its specimens are solved, in ``jobs`` processes."""
        return SolveSetup(self.unit, self.settings, self.steps_per_ramp, jobs)


@dataclass(frozen=True)
class CampaignInputs:
    """The files a campaign's diagnosis and ladder read."""

    measurements: str | Path   # the measurement file
    tables: list               # the per-specimen tables (Parquet)

    def read(self):
        """The checked measurements and the tables, concatenated."""
        table = pd.concat([pd.read_parquet(p) for p in self.tables], ignore_index=True)
        return load_measurements(self.measurements), table


def campaign_plan(name: str, camp: dict, fe: dict) -> CampaignPlan:
    """Resolve one campaign of the config.

    Parameters
    ----------
    name : str
        The campaign's name.
    camp : dict
        Its config (``validation: {NAME: ...}``), validated by the schema.
    fe : dict
        The config's ``fe`` section: the mesh and load steps where the campaign names none.

    Returns
    -------
    CampaignPlan
        ``effects`` split into fixed values and ``calibrate`` ones (which join the candidates),
        ``candidates: all`` resolved to the registered effects not fixed.
    """
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
                        int(camp.get("steps_per_ramp", fe["steps_per_ramp"])), camp.get("about", ""),
                        {e: {p: float(v) for p, v in ps.items()} for e, ps in camp.get("hidden_effects", {}).items()},
                        dict(camp.get("data_mesh", {})))


def campaign_specimens(plan: CampaignPlan) -> pd.DataFrame:
    """The campaign's specimens, read and checked from its measurement file.

    Parameters
    ----------
    plan : CampaignPlan
        The campaign.

    Returns
    -------
    pandas.DataFrame
        One row per specimen (``Measurements.specimens``).

    Raises
    ------
    InputError
        For every problem of the file (with file, row and field), a specimen of another drive
        or a specimen id that cannot name a file (``load_measurements`` with the campaign's drive),
        and curve points the campaign's test has no match for (``schedule_problems``).
    """
    meas = load_measurements(plan.measurements, unit=plan.unit)
    problems = schedule_problems(meas, plan.steps_per_ramp)
    if problems:
        raise MeasurementError(plan.measurements, problems)
    return meas.specimens


def specimen_record(specimens: pd.DataFrame, specimen_id: str) -> dict:
    """One specimen's id, drive and parameters, as plain values (a rule's ``params``).

    Parameters
    ----------
    specimens : pandas.DataFrame
        The campaign's specimens (``campaign_specimens``).
    specimen_id : str
        The specimen.

    Returns
    -------
    dict
        ``specimen_id``, ``unit`` and the ``*_mm`` columns.
    """
    row = specimens[specimens["specimen_id"] == specimen_id].iloc[0]
    return {k: (float(v) if k.endswith("_mm") else str(v)) for k, v in row.items()
            if k in ("specimen_id", "unit") or k.endswith("_mm")}


def diagnosis_stage(plan: CampaignPlan, inputs: CampaignInputs, out_json, out_points, provenance: dict,
                    jobs: int = 1) -> dict:
    """Diagnose one campaign from its measurement file and per-specimen tables.

    The solves that anchor an effect found before the next round run here, in ``jobs`` processes.

    Parameters
    ----------
    plan : CampaignPlan
        The campaign.
    inputs : CampaignInputs
        Its measurement file and tables.
    out_json, out_points : path
        ``diagnosis.json`` and the comparison points (Parquet).
    provenance : dict
        Stamped on both.
    jobs : int
        Processes of the re-solves.

    Returns
    -------
    dict
        The content of ``diagnosis.json``.
    """
    meas, table = inputs.read()
    solve = specimen_solver(plan.solve_setup(jobs), meas.specimens)
    from hdwf.validation.diagnosis import diagnose
    diagnosis = diagnose(meas, table, plan.search(), solve=solve)
    result = {"campaign": plan.name, "unit": plan.unit, "measurements": str(inputs.measurements),
              "about": plan.about, "mesh": plan.settings, **diagnosis.to_dict()}
    if plan.hidden_effects:
        result["hidden_effects"] = plan.hidden_effects
        if plan.data_mesh:
            result["data_mesh"] = plan.data_mesh
        result["recovery"] = recovery(plan.hidden_effects, result["found"],
                                      result["verdict"].get("found_in_order") or []).to_dict()
    result = json_safe({**result, "provenance": provenance})
    write_parquet(diagnosis.points, out_points, provenance=provenance, meta={"campaign": plan.name, "unit": plan.unit})
    write_json(result, out_json)
    return result


def ladder_stage(setup: SolveSetup, inputs: CampaignInputs, diagnosis_json, out, provenance: dict) -> pd.DataFrame:
    """The ladder of a campaign from actual solves (``hdwf.validation.ladder.solve_ladder``).

    Parameters
    ----------
    setup : SolveSetup
        Drive, mesh settings, load steps and processes of the solves a table lacks.
    inputs : CampaignInputs
        Its measurement file and tables.
    diagnosis_json : path
        The campaign's ``diagnosis.json``.
    out : path
        The ladder (Parquet).
    provenance : dict
        Stamped on the ladder.

    Returns
    -------
    pandas.DataFrame
        The ladder written.
    """
    meas, table = inputs.read()
    diag = read_json(diagnosis_json)
    rungs = ladder_variants(diag["model"]["fixed"], [(f["effect"], f["params"]) for f in diag["found"]])
    ladder, n_solved = solve_ladder(meas, table, rungs, setup)
    write_parquet(ladder, out, provenance=provenance,
                  meta={"campaign": diag["campaign"], "unit": diag["unit"], "solved_for_ladder": n_solved})
    return ladder


def figures_stage(diagnosis_json, points, ladder, out_measured, out_residuals, out_ladder,
                  provenance: dict | None = None) -> None:
    """Measured against predicted, the residuals and the ladder of a campaign (PNG).

    Parameters
    ----------
    diagnosis_json, points, ladder : path
        The campaign's ``diagnosis.json``, comparison points and ladder.
    out_measured, out_residuals, out_ladder : path
        The three figures.
    provenance : dict, optional
        Stamped in each PNG (``hdwf.report.figures.stamped``).
    """
    diag = read_json(diagnosis_json)
    pts = pd.read_parquet(points)
    name = f"{diag['campaign']} ({diag['unit'].upper()})"
    from hdwf.report.figures import ladder_figure, measured_vs_predicted_figure, residual_figure, stamped
    with stamped(provenance):
        measured_vs_predicted_figure(pts, f"{name}: measured against predicted", out_measured)
        residual_figure(pts, f"{name}: residuals", out_residuals)
        ladder_figure(pd.read_parquet(ladder), diag.get("noise_arcmin"), f"{name}: the error ladder", out_ladder)
