"""Input–output correlation as in the paper's Sect. 6: multiple linear regression
(statsmodels OLS), Pearson's r and Spearman's ρ (scipy) of each parameter with Φ."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import statsmodels.api as sm
from scipy import stats

from hdwf import PARAMETER_COLUMNS, PARAMETERS

CORRELATION_COLUMNS = ["parameter", "pearson_r", "pearson_p", "spearman_rho", "spearman_p",
                       "ols_coef", "ols_std_coef", "ols_p"]


@dataclass(frozen=True)
class RegressionSummary:
    r2: float
    r2_adj: float
    f_pvalue: float
    intercept: float
    n: int


def correlation(designs: pd.DataFrame, response: str = "lost_motion_arcmin") -> tuple[pd.DataFrame, RegressionSummary]:
    """Per-parameter correlation table and the multiple-regression summary.

    Only rows with a finite response are used (failed designs carry a null Φ). The
    standardised OLS coefficient is b·s_x/s_y: the change of Φ in standard deviations per
    standard deviation of the input, comparable across parameters of different units.
    """
    ok = designs[np.isfinite(designs[response].to_numpy(dtype=float))]
    if len(ok) < len(PARAMETERS) + 2:
        raise ValueError(f"correlation needs at least {len(PARAMETERS) + 2} designs with a result, got {len(ok)}")
    X = ok[list(PARAMETER_COLUMNS)].to_numpy(dtype=float)
    y = ok[response].to_numpy(dtype=float)
    fit = sm.OLS(y, sm.add_constant(X)).fit()
    s_y = y.std(ddof=1)
    rows = []
    for j, p in enumerate(PARAMETERS):
        x = X[:, j]
        pr = stats.pearsonr(x, y)
        sr = stats.spearmanr(x, y)
        rows.append({
            "parameter": p,
            "pearson_r": float(pr.statistic), "pearson_p": float(pr.pvalue),
            "spearman_rho": float(sr.statistic), "spearman_p": float(sr.pvalue),
            "ols_coef": float(fit.params[j + 1]),
            "ols_std_coef": float(fit.params[j + 1] * x.std(ddof=1) / s_y),
            "ols_p": float(fit.pvalues[j + 1]),
        })
    summary = RegressionSummary(r2=float(fit.rsquared), r2_adj=float(fit.rsquared_adj),
                                f_pvalue=float(fit.f_pvalue), intercept=float(fit.params[0]), n=len(y))
    return pd.DataFrame(rows, columns=CORRELATION_COLUMNS), summary
