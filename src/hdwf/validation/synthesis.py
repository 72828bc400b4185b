"""Synthetic measurements: specimens drawn over design ranges, their FE curves, noise.

Specimens are a seeded Latin hypercube over the paper's Table 3 ranges, or over narrower
ranges for a batch like the one on a bench (``design_ranges``; ``--range NAME=LOW:HIGH`` on
the command line, ``parse_range``). Their measured curves are the FE model's with some effects
switched on (``synth_curves``) plus seeded Gaussian noise (``add_noise``), in the curve form of
``docs/measurements.md`` (``synthesize``).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.stats import qmc

from hdwf import PARAMETER_COLUMNS, PARAMETERS
from hdwf.common.errors import SolveFailed
from hdwf.validation.effects import model_changes
from hdwf.validation.measurements import TABLE3_BOUNDS, supported_bounds
from hdwf.validation.variants import SolveSetup, specimen_solver


def design_ranges(unit: str, ranges: dict[str, tuple[float, float]] | None = None
                  ) -> dict[str, tuple[float, float]]:
    """The sampling range of every parameter column.

    Parameters
    ----------
    unit : str
        The drive.
    ranges : dict, optional
        ``{column: (low, high)}`` replacing Table 3's range of those columns; each must lie
        inside what the model supports (``measurements.supported_bounds``).

    Returns
    -------
    dict
        ``{column: (low, high)}`` for every parameter column.

    Raises
    ------
    ValueError
        For an unknown drive or column, a range that is not two finite numbers with
        low <= high, or one outside the model's support.
    """
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
    """One design range as written on the command line (``--range``).

    Parameters
    ----------
    text : str
        ``NAME=LOW:HIGH``, e.g. ``"rFS_mm=0:0.002"``.

    Returns
    -------
    tuple
        ``(name, low, high)``, e.g. ``("rFS_mm", 0.0, 0.002)``.

    Raises
    ------
    ValueError
        When ``text`` is not of that form.
    """
    name, sep, rest = text.partition("=")
    low, sep2, high = rest.partition(":")
    try:
        if not (sep and sep2 and name.strip()):
            raise ValueError
        return name.strip(), float(low), float(high)
    except ValueError:
        raise ValueError(f"expected NAME=LOW:HIGH (e.g. rFS_mm=0:0.002), got {text!r}") from None


def format_ranges(ranges: dict[str, tuple[float, float]]) -> str:
    """The design ranges for a printed summary.

    Parameters
    ----------
    ranges : dict
        ``{column: (low, high)}``.

    Returns
    -------
    str
        ``", rFS_mm 0..0.002, ..."``, or ``""`` for no ranges.
    """
    return "".join(f", {c} {lo:g}..{hi:g}" for c, (lo, hi) in ranges.items())


def synth_designs(unit: str, n: int, seed: int,
                  ranges: dict[str, tuple[float, float]] | None = None) -> pd.DataFrame:
    """Specimens by a seeded Latin hypercube over the design ranges.

    Parameters
    ----------
    unit : str
        The drive.
    n : int
        Number of specimens.
    seed : int
        Seed of the Latin hypercube.
    ranges : dict, optional
        ``{column: (low, high)}`` instead of Table 3's ranges (``design_ranges``), e.g.
        ``{"rFS_mm": (0, 0.002)}``: a batch like the one on the bench rather than the paper's
        design space (docs/validation.md).

    Returns
    -------
    pandas.DataFrame
        ``specimen_id`` (``<unit>-s001`` …), ``unit`` and the parameter columns.
    """
    bounds = design_ranges(unit, ranges)
    lo = np.array([bounds[c][0] for c in PARAMETER_COLUMNS])
    hi = np.array([bounds[c][1] for c in PARAMETER_COLUMNS])
    u = qmc.LatinHypercube(d=len(PARAMETERS), seed=seed).random(n)
    x = lo + u * (hi - lo)      # qmc.scale refuses a zero-width range; a fixed value is allowed
    df = pd.DataFrame(x, columns=list(PARAMETER_COLUMNS))
    df.insert(0, "unit", unit)
    df.insert(0, "specimen_id", [f"{unit}-s{i + 1:03d}" for i in range(n)])
    return df


def synth_curves(setup: SolveSetup, n_designs: int, seed: int,
                 effects: dict[str, dict[str, float]] | None = None,
                 ranges: dict[str, tuple[float, float]] | None = None) -> pd.DataFrame:
    """The noise-free curves ``synthesize`` starts from (one solve per specimen).

    Parameters
    ----------
    setup : SolveSetup
        Drive, mesh settings, load steps and processes.
    n_designs, seed : int
        Number of specimens and the seed of their Latin hypercube (``synth_designs``).
    effects : dict, optional
        The effects switched on, ``{effect: {param: value}}``; checked before any solve.
    ranges : dict, optional
        Design ranges instead of Table 3's (``design_ranges``).

    Returns
    -------
    pandas.DataFrame
        The specimens' columns with ``step``, ``torque_Nm`` and ``twist_arcmin``, one row per point.

    Raises
    ------
    SolveFailed
        When the solve of a specimen fails (no silent rows).
    """
    specimens = synth_designs(setup.unit, n_designs, seed, ranges)
    effects = effects or {}
    model_changes(effects)    # checks names, parameters and bounds before any solve
    table = specimen_solver(setup, specimens)([effects])
    bad = table[table["status"] != "ok"]
    if len(bad):
        raise SolveFailed(f"synthesis: the FE solve failed for specimen "
                           f"{bad['specimen_id'].iloc[0]}: {bad['status'].iloc[0]}")
    return specimens.merge(table[["specimen_id", "step", "torque_Nm", "twist_arcmin"]], on="specimen_id")


def add_noise(curves: pd.DataFrame, noise_arcmin: float, seed: int) -> pd.DataFrame:
    """Gaussian noise on every twist.

    Parameters
    ----------
    curves : pandas.DataFrame
        Noise-free curves (``synth_curves``).
    noise_arcmin : float
        Standard deviation of the noise.
    seed : int
        Seed of the ``numpy`` generator.

    Returns
    -------
    pandas.DataFrame
        The curve form of a measurement file, with ``u_twist_arcmin`` = ``noise_arcmin``; without
        that column for noise-free data (a stated uncertainty must be above zero).
    """
    rng = np.random.default_rng(seed)
    data = curves.copy()
    data["twist_arcmin"] = data["twist_arcmin"] + rng.normal(0.0, noise_arcmin, len(data))
    columns = ["specimen_id", "unit", *PARAMETER_COLUMNS, "step", "torque_Nm", "twist_arcmin"]
    if noise_arcmin > 0:
        data["u_twist_arcmin"] = noise_arcmin
        columns.append("u_twist_arcmin")
    return data[columns]


def synthesize(setup: SolveSetup, n_designs: int, seed: int, noise_arcmin: float,
               effects: dict[str, dict[str, float]] | None = None,
               ranges: dict[str, tuple[float, float]] | None = None) -> pd.DataFrame:
    """Measurements from the FE model with ``effects`` on, in the documented curve form.

    Parameters
    ----------
    setup, n_designs, seed, effects, ranges
        As for ``synth_curves``; ``seed`` also seeds the noise.
    noise_arcmin : float
        Standard deviation of the Gaussian noise (>= 0), also given as ``u_twist_arcmin``.

    Returns
    -------
    pandas.DataFrame
        The solved curve of each specimen plus the noise (``add_noise``).

    Raises
    ------
    ValueError
        For a negative or non-finite noise, bad ranges or effects.
    SolveFailed
        When a solve fails.
    """
    if noise_arcmin < 0 or not math.isfinite(noise_arcmin):
        raise ValueError(f"noise_arcmin must be >= 0, got {noise_arcmin!r}")
    return add_noise(synth_curves(setup, n_designs, seed, effects, ranges), noise_arcmin, seed)
