"""The noise of measured data: the stated uncertainty against the scatter the data show.

The estimate is the scatter of the residual r = D − S that no model term explains: for curves,
second differences along each branch (a play, loop or level error, constant along a branch, adds
nothing); for single values, the scatter after r's regression on the inputs. A stated
uncertainty absent, zero or ``NOISE_FLAG_RATIO`` below the estimate is flagged, and the estimate
is then what the signature and the detectability are read against (docs/validation.md, "The
residual's signature").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import statsmodels.api as sm

from hdwf import PARAMETER_COLUMNS

NOISE_FLAG_RATIO = 3.0     # a stated uncertainty this many times below the data's scatter is flagged


@dataclass(frozen=True)
class NoiseCheck:
    """The stated uncertainty against the scatter estimated from the data (``flag``: the stated one is
    absent, zero or more than ``NOISE_FLAG_RATIO`` below the estimate; ``note`` says so in words)."""

    stated_median_arcmin: float | None   # the median stated u, None when the data state none
    estimate_arcmin: float | None        # None when the data cannot give one
    estimate_from: str
    n_used: int                          # second differences, or residual degrees of freedom, behind it
    flag: bool
    note: str                            # "" without a flag

    @property
    def reference_arcmin(self) -> float | None:
        """The noise the signature is read against: the stated one unless flagged, else the estimate."""
        if not self.flag and self.stated_median_arcmin:
            return self.stated_median_arcmin
        return self.estimate_arcmin if self.estimate_arcmin else self.stated_median_arcmin or None


def _second_differences(c: pd.DataFrame) -> np.ndarray:
    """r[i-1] - 2 r[i] + r[i+1] along every branch of every specimen, leaving out the points before
    any load (a loop or a play error, constant along a branch, then adds nothing)."""
    out = []
    for _, g in c.groupby("specimen_id", sort=False):
        r, br, side = g["r"].to_numpy(float), g["branch"].to_numpy(), g["side"].to_numpy(float)
        start = 0
        for k in range(1, len(g) + 1):
            if k < len(g) and br[k] == br[k - 1]:
                continue
            x = r[[i for i in range(start, k) if side[i] != 0]]
            if len(x) >= 3:
                out.append(x[:-2] - 2.0 * x[1:-1] + x[2:])
            start = k
    return np.concatenate(out) if out else np.zeros(0)


def noise_estimate(points: pd.DataFrame, c: pd.DataFrame | None, r: np.ndarray) -> tuple[float | None, str, int]:
    """The noise from the data: second differences (curves) or the scatter after the inputs' regression."""
    if c is not None:
        d2 = _second_differences(c)
        if d2.size:
            return (float(np.sqrt(np.mean(d2 ** 2) / 6.0)),
                    "second differences of D - S along each branch (var = 6 sigma^2)", int(d2.size))
        return None, "too few points per branch for second differences", 0
    cols = [p for p in PARAMETER_COLUMNS if p in points and np.ptp(points[p].to_numpy(float)) > 0]
    X = points[cols].to_numpy(float) * 1000.0
    if "quantity" in points and points["quantity"].nunique() > 1:
        X = np.column_stack([X, pd.get_dummies(points["quantity"], drop_first=True, dtype=float).to_numpy()])
    X = sm.add_constant(X, has_constant="add")
    if len(r) - X.shape[1] < 3 or np.linalg.matrix_rank(X) < X.shape[1]:
        return None, "too few values for the scatter after the regression on the inputs", 0
    fit = sm.OLS(r, X).fit()
    return (float(np.sqrt(fit.ssr / fit.df_resid)), "scatter of D - S after its regression on the inputs",
            int(fit.df_resid))


def noise_check(stated: np.ndarray, estimate: float | None, estimate_from: str, n_used: int) -> NoiseCheck:
    """The stated uncertainty against the data's scatter, flagged when absent, zero or far below it.

    Parameters
    ----------
    stated : numpy.ndarray
        The stated uncertainty per value (NaN where none).
    estimate : float or None
        The noise estimated from the data.
    estimate_from, n_used
        How, and from how many values.

    Returns
    -------
    NoiseCheck
        With the note the report prints (when flagged, the diagnosis judges detectability by the estimate).
    """
    u = np.asarray(stated, float)
    med = float(np.median(u[np.isfinite(u)])) if np.isfinite(u).any() else None
    if not estimate or (med is not None and med * NOISE_FLAG_RATIO >= estimate):
        return NoiseCheck(med, estimate, estimate_from, n_used, False, "")
    if med is None:
        note = (f"no uncertainty is stated; the scatter estimated from the data is {estimate:.3g} arcmin "
                "(the detectability uses the final model's residual instead, an upper bound)")
        return NoiseCheck(med, estimate, estimate_from, n_used, True, note)
    note = (f"stated uncertainty {med:.3f} arcmin is far below the scatter {estimate:.3g} arcmin estimated from "
            "the data; the estimate is used to read this signature and to judge what the data can show (the "
            "detectability table). The verdict (ΔBIC, leave-one-out error) does not use the stated uncertainty; "
            "u_val does, so it understates the comparison's uncertainty")
    return NoiseCheck(med, estimate, estimate_from, n_used, True, note)
