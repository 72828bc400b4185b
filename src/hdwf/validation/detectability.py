"""What data could see: would each candidate, at its realistic value, show against the noise?

Each candidate at its realistic value changes the predictions by a vector Δ; against the
noise σ (stated, or else a model's residual, an upper bound) it would be found when the ΔBIC
it earns, -n ln(1 + |Δ|²/(n σ²)) + ln n, clears the pay threshold, and its parameter would come
out with relative standard deviation σ/|Δ| in t (linearised, other effects held; for a value
tabulated as value^-p that is σ/(p|Δ|) of the value). A diagnosis that finds no missing effect
therefore says which candidates its data could not have seen at all; before measuring,
``plan_detectability`` says which a test of given specimens at a given noise could show.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from hdwf.common.errors import SolveFailed
from hdwf.validation.calibration import Response, responses
from hdwf.validation.effects import get as get_effect
from hdwf.validation.variants import (SolveSetup, candidate_names, mean_lost_motion, plan_variants,
                                      specimen_solver, variant_key)


@dataclass(frozen=True)
class Visibility:
    """Whether data could show one candidate at its realistic value (changes in arcmin)."""

    effect: str
    param: str
    realistic: float
    unit: str
    change_rms_arcmin: float
    change_max_arcmin: float
    expected_delta_bic: float
    expected_rel_sd: float              # of the calibrated parameter
    noise_to_show_arcmin: float         # the noise at which it would just pay
    noise_to_calibrate_arcmin: float    # ... at which its parameter comes out within 15 % at 2 sd
    visible: bool

    def as_dict(self) -> dict:
        """The row as ``diagnosis.json`` and ``hdwf plan --out`` give it."""
        return asdict(self)


def detectability(resp: dict[str, Response], noise: float, n: int, unit: str | None = None,
                  pay_threshold: float = 10.0) -> list[Visibility]:
    """Could this data show each candidate at its realistic value for ``unit``?

    Parameters
    ----------
    resp : dict
        ``{effect: Response}`` of the candidates.
    noise : float
        Standard deviation of one observation (arcmin).
    n : int
        Number of observations.
    unit : str, optional
        The drive, where it sets the realistic value.
    pay_threshold : float
        The ΔBIC a candidate must earn.

    Returns
    -------
    list of Visibility
        One per candidate: the change at the realistic value, the ΔBIC it would earn, the
        relative sd of its calibrated parameter and the noise at which it would just pay or
        be calibrated.
    """
    need = pay_threshold + math.log(n)      # -ΔBIC to pay, when adding one parameter
    rows = []
    for name, r in resp.items():
        p = get_effect(name).param(r.param)
        realistic = p.realistic_for(unit)
        t = p.to_t(realistic)
        delta = r.change(t)
        size = float(np.linalg.norm(delta))
        # relative sd of the value per relative sd of t (1, or 1/power for value**-power)
        stretch = p.sd_from_t(t, t) / realistic if t != 0 else 1.0
        chi2 = (size / noise) ** 2 if noise > 0 else math.inf
        # the noise s that solves n ln(1 + size²/(n s²)) = need
        show = size / math.sqrt(n * math.expm1(need / n)) if size > 0 else 0.0
        rows.append(Visibility(
            effect=name, param=r.param, realistic=realistic, unit=p.unit,
            change_rms_arcmin=size / math.sqrt(n), change_max_arcmin=float(np.max(np.abs(delta))),
            expected_delta_bic=float(-n * math.log1p(chi2 / n) + math.log(n)) if math.isfinite(chi2) else -math.inf,
            expected_rel_sd=(stretch / math.sqrt(chi2)) if chi2 > 0 else math.inf,
            noise_to_show_arcmin=show, noise_to_calibrate_arcmin=0.075 * size / stretch,
            visible=bool(size > 0 and noise < show)))
    return rows


@dataclass(frozen=True)
class DetectabilityPlan:
    """What a test of given specimens at a given noise could show, before measuring."""

    unit: str
    n_specimens: int
    n_points: int
    noise_arcmin: float
    mean_lost_motion_arcmin: float
    pay_threshold: float
    notes: dict[str, str]               # {effect: why (part of) its grid is missing}
    candidates: list[Visibility]

    def to_dict(self) -> dict:
        """The plan as ``hdwf plan --out`` writes it."""
        return asdict(self)


def detectability_of_tables(table: pd.DataFrame, unit: str, noise_arcmin: float,
                            candidates: list[str], pay_threshold: float = 10.0) -> DetectabilityPlan:
    """``plan_detectability`` on tables already solved (every step of every specimen observed).

    Parameters
    ----------
    table : pandas.DataFrame
        The baseline and every candidate's grid, solved for each specimen.
    unit : str
        The drive.
    noise_arcmin : float
        Standard deviation of one reading.
    candidates : list of str
        The effects whose grids the tables hold.
    pay_threshold : float
        The ΔBIC a candidate must earn.

    Returns
    -------
    DetectabilityPlan
        The candidates' ``Visibility`` on the curve form of the test.
    """
    base = table[table["variant"] == variant_key({})]
    bad = base[base["status"] != "ok"]
    if len(bad):
        raise SolveFailed(f"the baseline solve failed for specimen {bad['specimen_id'].iloc[0]}: "
                           f"{bad['status'].iloc[0]}")
    obs = base[["specimen_id", "step", "torque_Nm"]].reset_index(drop=True)
    obs["quantity"] = "twist"
    notes: dict[str, str] = {}
    resp = responses(table, obs, {}, candidates, notes)
    return DetectabilityPlan(unit, int(base["specimen_id"].nunique()), int(len(obs)), float(noise_arcmin),
                             mean_lost_motion(table), pay_threshold, notes,
                             detectability(resp, noise_arcmin, len(obs), unit, pay_threshold))


def plan_detectability(setup: SolveSetup, specimens: pd.DataFrame, noise_arcmin: float,
                       candidates: list[str] | None = None, pay_threshold: float = 10.0) -> DetectabilityPlan:
    """Before measuring: which candidates could a test of these specimens show at this noise?

    Solves the campaign tables of ``specimens`` (the baseline model and every candidate's
    grid, as a campaign would) and evaluates ``detectability`` on the curve form of the test
    (every step of every specimen).

    Parameters
    ----------
    setup, specimens
        How and which specimens are solved (``hdwf.validation.variants.solve_specimens``).
    noise_arcmin : float
        Standard deviation of one reading (> 0).
    candidates : list of str, optional
        The effects to consider (default: every registered one).
    pay_threshold : float
        The ΔBIC a candidate must earn.

    Returns
    -------
    DetectabilityPlan
        The candidates' ``Visibility``.
    """
    if not (noise_arcmin > 0 and math.isfinite(noise_arcmin)):
        raise ValueError(f"noise_arcmin must be > 0, got {noise_arcmin!r}")
    candidates = candidate_names({}) if candidates is None else list(candidates)
    table = specimen_solver(setup, specimens)(plan_variants({}, candidates))
    return detectability_of_tables(table, setup.unit, noise_arcmin, candidates, pay_threshold)
