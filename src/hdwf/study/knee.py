"""The knee of lost motion against clearance: a hinge fit, and the least-squares offset slope.

A preloaded tooth engagement absorbs the first micrometres of tooth offset and radial
shortfall; only past that *knee* does backlash open. Over a design table this shows as a hinge,

    Φ = floor + slope · max(0, s − knee),   s = r_FS + r_CS + w_d Δd/2 + w_D ΔD/2 + w_G ΔG_r/2,

all lengths in µm and Δ measured from Table 3's nominal design. The weights say how much of each
radial change reaches the flank clearance; they are fitted with the rest (six parameters,
``scipy.optimize.least_squares`` from a few starts, deterministic). A model without preload has
no flat part: its knee lies below the smallest s of the table.

``offset_slopes`` is the plainer number: dΦ/dr_FS and dΦ/dr_CS of a linear least-squares fit in
all five parameters (arcmin/µm).

``floor_ranks`` says where a model's rank against a reference (the paper's Φ) is won or lost: on
the reference's flat part or past its knee. It also gives what the reference's own hinge would
rank, and the linear trend hidden in its "flat" part, which a hinge cannot rank.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
import pandas as pd
import statsmodels.api as sm
from scipy.optimize import least_squares
from scipy.stats import rankdata, spearmanr

from hdwf import PARAMETER_COLUMNS

RADIAL = ("d_mm", "D_mm", "Gr_mm")   # the radial changes weighted into the clearance, in this order
MIN_FLOOR_DESIGNS = 11               # a linear fit in five parameters with 5 degrees of freedom left
# every radial loosening (a looser bore, a smaller outer ring, more clearance) counting like an offset;
# the paper's own hinge weights are 1.1-1.2 for d and G_r (HD 42) and for d and D (HD 120)
EQUAL_WEIGHTS = (1.0, -1.0, 1.0)


@dataclass(frozen=True)
class HingeFit:
    """A hinge Φ = floor + slope · max(0, s − knee) fitted to a design table.

    Attributes
    ----------
    floor_arcmin : float
        Lost motion on the flat part (designs whose clearance the preload takes up).
    slope_arcmin_per_um : float
        Rise of Φ per µm of clearance past the knee.
    knee_um : float
        Clearance s (µm) where the flat part ends.
    weights : tuple of float
        w_d, w_D, w_G: µm of clearance per µm of Δd/2, ΔD/2, ΔG_r/2.
    r2 : float
        Coefficient of determination of the fit.
    n : int
        Designs fitted.
    """

    floor_arcmin: float
    slope_arcmin_per_um: float
    knee_um: float
    weights: tuple[float, float, float]
    r2: float
    n: int

    def clearance_um(self, designs: pd.DataFrame, nominal: Mapping[str, float]) -> np.ndarray:
        """The clearance s (µm) of each design under this fit's weights."""
        return clearance_um(designs, nominal, self.weights)

    def predict(self, clearance: np.ndarray) -> np.ndarray:
        """Φ (arcmin) of the hinge at clearances s (µm)."""
        return self.floor_arcmin + self.slope_arcmin_per_um * np.maximum(0.0, np.asarray(clearance) - self.knee_um)


def _clearance_terms(designs: pd.DataFrame, nominal: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """r_FS + r_CS and the half radial changes Δk/2 (one column per ``RADIAL``), in µm."""
    half_changes = 1e3 * np.column_stack([(designs[c].to_numpy(float) - nominal[c]) / 2.0 for c in RADIAL])
    offsets = 1e3 * (designs["rFS_mm"].to_numpy(float) + designs["rCS_mm"].to_numpy(float))
    return offsets, half_changes


def clearance_um(designs: pd.DataFrame, nominal: Mapping[str, float], weights) -> np.ndarray:
    """s = r_FS + r_CS + Σ w_k Δk/2 in µm, Δ from the nominal design (columns ``*_mm``)."""
    offsets, half_changes = _clearance_terms(designs, nominal)
    return offsets + half_changes @ np.asarray(weights, float)


def fit_hinge(designs: pd.DataFrame, nominal: Mapping[str, float],
              column: str = "lost_motion_arcmin") -> HingeFit:
    """Least-squares hinge of ``column`` against the clearance, weights fitted.

    Parameters
    ----------
    designs : DataFrame
        One row per design: ``d_mm, D_mm, Gr_mm, rFS_mm, rCS_mm`` and ``column``; rows with a
        missing Φ (failed solves) are left out.
    nominal : Mapping
        Table 3's nominal design, the same columns (mm).
    column : str
        The lost-motion column.

    Returns
    -------
    HingeFit
        The best of several starts (knee at the 10th to 90th percentile of r_FS + r_CS).
    """
    table = designs[np.isfinite(designs[column].to_numpy(float))]
    if len(table) < 7:
        raise ValueError(f"a hinge in six parameters needs at least 7 designs, got {len(table)}")
    y = table[column].to_numpy(float)
    offsets, half_changes = _clearance_terms(table, nominal)

    def residual(p):
        floor, slope, knee, *w = p
        return floor + slope * np.maximum(0.0, offsets + half_changes @ np.asarray(w) - knee) - y

    best = None
    for knee in np.percentile(offsets, [10, 30, 50, 70, 90]):
        for w in ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (1.0, -1.0, 1.0)):
            fit = least_squares(residual, [y.min(), (y.max() - y.min()) / max(np.ptp(offsets), 1e-9), knee, *w])
            if best is None or fit.cost < best.cost:
                best = fit
    floor, slope, knee, *w = best.x
    r2 = 1.0 - 2.0 * best.cost / float(np.sum((y - y.mean()) ** 2))
    return HingeFit(float(floor), float(slope), float(knee), tuple(float(v) for v in w), float(r2), len(table))


def offset_slopes(designs: pd.DataFrame, column: str = "lost_motion_arcmin") -> tuple[float, float]:
    """dΦ/dr_FS and dΦ/dr_CS (arcmin/µm) of a linear least-squares fit in the five parameters.

    Parameters
    ----------
    designs : DataFrame
        One row per design with the five ``*_mm`` columns and ``column``; missing Φ left out.
    column : str
        The lost-motion column.

    Returns
    -------
    tuple of float
        The coefficients of r_FS and r_CS per µm.
    """
    table = designs[np.isfinite(designs[column].to_numpy(float))]
    phi = table[column].to_numpy(float)
    weights = offset_slope_weights(table)
    return float(weights["rFS_mm"] @ phi), float(weights["rCS_mm"] @ phi)


def offset_slope_weights(designs: pd.DataFrame) -> dict[str, np.ndarray]:
    """Per offset column, the weights w with w · Φ = its least-squares coefficient (arcmin/µm) over
    ``designs``' rows (a linear fit in the five parameters): the slope of any Φ on these designs,
    e.g. of many perturbed copies at once."""
    A = np.column_stack([np.ones(len(designs)), designs[list(PARAMETER_COLUMNS)].to_numpy(float)])
    rows = dict(zip(("intercept", *PARAMETER_COLUMNS), np.linalg.pinv(A)))
    return {c: rows[c] * 1e-3 for c in ("rFS_mm", "rCS_mm")}


@dataclass(frozen=True)
class FloorRanks:
    """A model's rank against a reference, split at the reference's knee.

    Attributes
    ----------
    n, n_floor : int
        Designs compared (both Φ known), and those on the reference's flat part (s below its knee).
    floor_coefficients : tuple of float
        The reference's Φ on its flat part, a linear fit in d, D, G_r, r_FS, r_CS: arcmin per µm of
        each (of the diameter for d and D); NaN with fewer than ``MIN_FLOOR_DESIGNS`` flat designs.
    floor_r2, floor_p : float
        R² of that fit and the p-value of its F-test (is the flat part flat?).
    spearman_hinge : float
        Spearman ρ of the reference against its own hinge, the flat designs tied.
    spearman_ceiling : float
        The same with the flat designs' order random (a model with the reference's hinge but not its
        flat part's trend), mean over the draws.
    share_at_least : float
        Share of those draws whose ρ reaches ``threshold``.
    spearman_clearance : float
        Spearman ρ of the reference against its clearance s with ``EQUAL_WEIGHTS``: what any model
        whose Φ rises strictly with that s would rank.
    threshold : float
        The rank target the share counts.
    spearman_all, spearman_floor, spearman_past : float
        Spearman ρ of the model against the reference: all designs, the flat ones, those past the knee.
    """

    n: int
    n_floor: int
    floor_coefficients: tuple[float, ...]
    floor_r2: float
    floor_p: float
    spearman_hinge: float
    spearman_ceiling: float
    share_at_least: float
    spearman_clearance: float
    threshold: float
    spearman_all: float
    spearman_floor: float
    spearman_past: float


def _rho(a: np.ndarray, b: np.ndarray) -> float:
    return float(spearmanr(a, b)[0]) if len(a) >= 3 else float("nan")


def _pearson_rows(x: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Pearson's r of ``x`` with each row of ``rows`` (Spearman's rho when both are ranks)."""
    xc = x - x.mean()
    rc = rows - rows.mean(axis=1, keepdims=True)
    return (rc @ xc) / (np.linalg.norm(rc, axis=1) * np.linalg.norm(xc))


def floor_ranks(reference: pd.DataFrame, model_arcmin: np.ndarray, nominal: Mapping[str, float], *,
                threshold: float = 0.9, draws: int = 2000, seed: int = 0,
                column: str = "lost_motion_arcmin") -> FloorRanks:
    """Split the rank of ``model_arcmin`` against ``reference`` at the reference's knee.

    Parameters
    ----------
    reference : DataFrame
        One row per design: the five ``*_mm`` columns and ``column`` (e.g. the paper's Table 4).
    model_arcmin : array
        The model's Φ at the same designs, in the same order; NaN where a solve failed.
    nominal : Mapping
        Table 3's nominal design (the origin of the clearance s).
    threshold : float
        The rank target whose reach the random-order draws count.
    draws, seed : int
        Random orders of the flat designs, seeded.
    column : str
        The reference's lost-motion column.

    Returns
    -------
    FloorRanks
    """
    model = np.asarray(model_arcmin, float)
    if len(model) != len(reference):
        raise ValueError(f"model has {len(model)} values for {len(reference)} reference designs")
    keep = np.isfinite(model) & np.isfinite(reference[column].to_numpy(float))
    table, model = reference[keep].reset_index(drop=True), model[keep]
    fit = fit_hinge(table, nominal, column)
    y = table[column].to_numpy(float)
    s = fit.clearance_um(table, nominal)
    flat = s < fit.knee_um
    hinge = fit.predict(s)

    floor = table[flat]
    coefficients, r2, p = (float("nan"),) * len(PARAMETER_COLUMNS), float("nan"), float("nan")
    if len(floor) >= MIN_FLOOR_DESIGNS:
        X = sm.add_constant(1e3 * (floor[list(PARAMETER_COLUMNS)] - pd.Series(nominal)[list(PARAMETER_COLUMNS)]),
                            has_constant="add")
        ols = sm.OLS(floor[column].to_numpy(float), X).fit()
        coefficients = tuple(float(ols.params[c]) for c in PARAMETER_COLUMNS)
        r2, p = float(ols.rsquared), float(ols.f_pvalue)

    rng = np.random.default_rng(seed)
    ordered = np.tile(hinge, (draws, 1))
    # the flat designs keep their common value, in a random order far finer than any step of the hinge
    ordered[:, flat] += 1e-9 * rng.permuted(np.tile(np.arange(flat.sum()), (draws, 1)), axis=1)
    rhos = _pearson_rows(rankdata(y), rankdata(ordered, axis=1))
    return FloorRanks(n=len(table), n_floor=int(flat.sum()), floor_coefficients=coefficients, floor_r2=r2, floor_p=p,
                      spearman_hinge=_rho(y, hinge), spearman_ceiling=float(rhos.mean()),
                      share_at_least=float(np.mean(rhos >= threshold)),
                      spearman_clearance=_rho(y, clearance_um(table, nominal, EQUAL_WEIGHTS)), threshold=threshold,
                      spearman_all=_rho(y, model), spearman_floor=_rho(y[flat], model[flat]),
                      spearman_past=_rho(y[~flat], model[~flat]))
