"""Designs of experiments, all from ``scipy.stats.qmc``.

* ``optimal_lhs``: the study design, a Latin hypercube optimised for space filling (the
  paper's "optimal space-filling design"), with its criteria recorded.
* ``unit_sample``: the LHS, Halton and Sobol' base samples of the Sobol-index stage.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.spatial.distance import pdist
from scipy.stats import qmc

from hdwf import PARAMETER_COLUMNS, PARAMETERS

SAMPLERS = ("lhs", "halton", "sobol")


def unit_sample(sampler: str, n: int, dim: int, seed: int) -> np.ndarray:
    """``n`` points in [0, 1)^dim from ``sampler`` (``lhs``, ``halton`` or ``sobol``), seeded."""
    rng = np.random.default_rng(seed)
    if sampler == "lhs":
        engine = qmc.LatinHypercube(d=dim, rng=rng)
    elif sampler == "halton":
        engine = qmc.Halton(d=dim, scramble=True, rng=rng)
    elif sampler == "sobol":
        if n & (n - 1):
            raise ValueError(f"Sobol' samples need a power of two, got n = {n}")
        engine = qmc.Sobol(d=dim, scramble=True, rng=rng)
    else:
        raise ValueError(f"unknown sampler '{sampler}'; choose one of {SAMPLERS}")
    return engine.random(n)


def scale(unit_points: np.ndarray, lower, upper) -> np.ndarray:
    return qmc.scale(unit_points, np.asarray(lower, float), np.asarray(upper, float))


@dataclass(frozen=True)
class SpaceFilling:
    """Space-filling criteria of a design in the unit cube (lower discrepancy, larger distance: better)."""

    centered_l2_discrepancy: float
    maximin_distance: float      # smallest distance between two points
    max_abs_correlation: float   # largest |Pearson r| between two columns


def space_filling(unit_points: np.ndarray) -> SpaceFilling:
    corr = np.corrcoef(unit_points, rowvar=False)
    off = np.abs(corr[~np.eye(len(corr), dtype=bool)])
    return SpaceFilling(
        centered_l2_discrepancy=float(qmc.discrepancy(unit_points, method="CD")),
        maximin_distance=float(pdist(unit_points).min()),
        max_abs_correlation=float(off.max()),
    )


def to_unit(values: np.ndarray, lower, upper) -> np.ndarray:
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    return (np.asarray(values, float) - lower) / (upper - lower)


def optimal_lhs(bounds: dict[str, tuple[float, float]], n: int = 27, seed: int = 0,
                optimization: str = "random-cd", prefix: str = "lhs") -> tuple[pd.DataFrame, SpaceFilling]:
    """An optimised Latin hypercube of ``n`` designs over ``bounds`` (parameter -> (min, max), mm).

    ``optimization`` is scipy's: ``random-cd`` minimises the centered L2 discrepancy by
    column swaps while keeping the LHS property; ``lloyd`` moves points apart (Voronoi) and
    gives up exact stratification; ``none`` is a plain LHS. Returns the design table (with
    ``design_id``) and its space-filling criteria.
    """
    lower = [bounds[p][0] for p in PARAMETERS]
    upper = [bounds[p][1] for p in PARAMETERS]
    opt = None if optimization == "none" else optimization
    engine = qmc.LatinHypercube(d=len(PARAMETERS), optimization=opt, rng=np.random.default_rng(seed))
    unit = engine.random(n)
    values = scale(unit, lower, upper)
    df = pd.DataFrame(values, columns=list(PARAMETER_COLUMNS))
    df.insert(0, "design_id", [f"{prefix}-{i + 1:02d}" for i in range(n)])
    return df, space_filling(unit)
