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
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from hdwf import PARAMETER_COLUMNS

RADIAL = ("d_mm", "D_mm", "Gr_mm")   # the radial changes weighted into the clearance, in this order


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
    A = np.column_stack([np.ones(len(table)), table[list(PARAMETER_COLUMNS)].to_numpy(float)])
    coef = dict(zip(("intercept", *PARAMETER_COLUMNS), np.linalg.lstsq(A, table[column].to_numpy(float), rcond=None)[0]))
    return float(coef["rFS_mm"]) * 1e-3, float(coef["rCS_mm"]) * 1e-3
