"""Model against measurements: comparison error, validation uncertainty, residual tests.

ASME V&V 20 vocabulary: S the simulation, D the measured value, comparison error
E = S − D, validation uncertainty u_val = √(u_num² + u_input² + u_D²); |E| well above
2·u_val points to model-form error. Residual tests use statsmodels: a regression of the
per-specimen error on the five inputs (does the error follow a design parameter?), Ramsey's
RESET on measured-versus-predicted (is the relation non-linear?), and a regression of the
error on torque and load branch (where along the curve does the model fail?).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from hdwf import PARAMETER_COLUMNS

BRANCHES = ("load+", "unload+", "load-", "unload-")


def branches(torque: np.ndarray) -> list[str]:
    """Label each point of a 0 → +T → 0 → −T → 0 test by its branch.

    A point belongs to the branch it was reached on: |T| rising gives ``load±``, falling
    ``unload±``; the sign is that of the torque (zero-torque points take the branch they end).

    Parameters
    ----------
    torque : array_like
        The torque of each point, in test order.

    Returns
    -------
    list of str
        ``load+``, ``unload+``, ``load-`` or ``unload-`` per point.
    """
    t = np.asarray(torque, float)
    out, prev, sign = [], 0.0, 1.0
    for x in t:
        if x != 0:
            sign = np.sign(x)
        rising = abs(x) > abs(prev) or (abs(x) == abs(prev) == 0 and not out)
        out.append(("load" if rising else "unload") + ("+" if sign > 0 else "-"))
        prev = x
    return out


def comparison_points(measured: pd.DataFrame, predicted: pd.DataFrame, value: str) -> pd.DataFrame:
    """Join measured and predicted values point by point.

    Both frames carry ``specimen_id`` and, for curves, ``step``; ``value`` names the compared
    column (``twist_arcmin`` or ``lost_motion_arcmin``...).

    Parameters
    ----------
    measured, predicted : pandas.DataFrame
        Measured and predicted values, keyed by ``specimen_id`` (and ``step``).
    value : str
        The compared column.

    Returns
    -------
    pandas.DataFrame
        The measured rows with D, S, E = S − D and u_D (from ``u_twist_arcmin`` / ``u_arcmin``
        when the data give it, else NaN); curves also get their ``branch``.
    """
    keys = ["specimen_id"] + (["step"] if "step" in measured.columns and "step" in predicted.columns else [])
    u_col = next((c for c in ("u_twist_arcmin", "u_arcmin") if c in measured.columns), None)
    left = measured.rename(columns={value: "D"})
    right = predicted[keys + [value]].rename(columns={value: "S"})
    pts = left.merge(right, on=keys, how="left", validate="one_to_one")
    missing = pts["S"].isna()
    if missing.any():
        raise ValueError(f"no prediction for {int(missing.sum())} measured point(s), e.g. specimen "
                         f"{pts.loc[missing, 'specimen_id'].iloc[0]!r}")
    pts["E"] = pts["S"] - pts["D"]
    pts["u_D"] = pts[u_col] if u_col else np.nan
    if "torque_Nm" in pts.columns and "step" in keys:
        pts = pts.sort_values(keys).reset_index(drop=True)
        pts["branch"] = np.concatenate([branches(g["torque_Nm"].to_numpy()) for _, g in
                                        pts.groupby("specimen_id", sort=False)])
    return pts


@dataclass(frozen=True)
class Summary:
    """Overall figures of a comparison (arcmin)."""

    n: int
    rmse: float
    bias: float
    max_abs: float
    worst_specimen: str
    u_val: float          # root-mean-square validation uncertainty (NaN without noise information)
    share_beyond_2uval: float  # share of points with |E| > 2 u_val (NaN without noise information)


def summarise(points: pd.DataFrame, u_num: float = 0.0, u_input: float = 0.0) -> tuple[Summary, pd.DataFrame]:
    """Overall figures and one row per specimen (rmse, bias, largest |E|).

    Parameters
    ----------
    points : pandas.DataFrame
        Comparison points (``comparison_points``).
    u_num, u_input : float
        Numerical and input uncertainty (arcmin) of the simulation, for u_val.

    Returns
    -------
    tuple
        The ``Summary`` and a frame of the specimens, worst first.
    """
    E = points["E"].to_numpy(float)
    per = points.groupby("specimen_id", sort=False)["E"].agg(
        rmse_arcmin=lambda e: float(np.sqrt(np.mean(np.square(e)))), bias_arcmin="mean",
        max_abs_arcmin=lambda e: float(np.max(np.abs(e))), n="size").reset_index()
    u_D = points["u_D"].to_numpy(float)
    u_val = np.sqrt(u_num ** 2 + u_input ** 2 + u_D ** 2)
    has_noise = np.isfinite(u_val).all()
    summary = Summary(n=len(E), rmse=float(np.sqrt(np.mean(E ** 2))), bias=float(E.mean()),
                      max_abs=float(np.abs(E).max()),
                      worst_specimen=str(per.sort_values("rmse_arcmin").iloc[-1]["specimen_id"]),
                      u_val=float(np.sqrt(np.mean(u_val ** 2))) if has_noise else float("nan"),
                      share_beyond_2uval=float(np.mean(np.abs(E) > 2 * u_val)) if has_noise else float("nan"))
    return summary, per.sort_values("rmse_arcmin", ascending=False).reset_index(drop=True)


def residual_tests(points: pd.DataFrame) -> pd.DataFrame:
    """statsmodels tests on the comparison error, with p-values (small p: a pattern the model misses).

    Parameters
    ----------
    points : pandas.DataFrame
        Comparison points (``comparison_points``) with the parameter columns.

    Returns
    -------
    pandas.DataFrame
        One row per test: ``test``, ``statistic``, ``p_value``, ``meaning``.
    """
    # statsmodels here only: the specimen and ladder jobs, which never test residuals, start faster
    import statsmodels.api as sm
    from statsmodels.stats.diagnostic import linear_reset

    rows = []
    spec = points.groupby("specimen_id", sort=False).agg(E=("E", "mean"), **{c: (c, "first") for c in PARAMETER_COLUMNS})
    X = spec[list(PARAMETER_COLUMNS)].to_numpy(float)
    varying = X.std(axis=0) > 0
    if len(spec) > varying.sum() + 2 and varying.any():
        fit = sm.OLS(spec["E"].to_numpy(float), sm.add_constant(X[:, varying])).fit()
        rows.append({"test": "error ~ inputs (OLS F-test)", "statistic": float(fit.fvalue), "p_value": float(fit.f_pvalue),
                     "meaning": "the per-specimen error follows the design parameters"})
        for name, p in zip(np.array(PARAMETER_COLUMNS)[varying], fit.pvalues[1:]):
            rows.append({"test": f"error ~ inputs: {name}", "statistic": float("nan"), "p_value": float(p),
                         "meaning": f"the error changes with {name} with the other inputs held "
                                    "(a coefficient of the regression on all the varying inputs, not a trend with it alone)"})
    if len(points) > 5 and points["S"].std() > 0:
        base = sm.OLS(points["D"].to_numpy(float), sm.add_constant(points["S"].to_numpy(float))).fit()
        reset = linear_reset(base, power=3, use_f=True)
        rows.append({"test": "RESET on measured ~ predicted", "statistic": float(reset.statistic),
                     "p_value": float(reset.pvalue), "meaning": "measured and predicted are not linearly related"})
    if "branch" in points.columns and "torque_Nm" in points.columns:
        design = pd.get_dummies(points["branch"], drop_first=True, dtype=float)
        design["abs_torque"] = points["torque_Nm"].abs()
        fit = sm.OLS(points["E"].to_numpy(float), sm.add_constant(design.to_numpy(float))).fit()
        rows.append({"test": "error ~ |torque| + branch (OLS F-test)", "statistic": float(fit.fvalue),
                     "p_value": float(fit.f_pvalue), "meaning": "the error depends on where along the curve"})
    return pd.DataFrame(rows, columns=["test", "statistic", "p_value", "meaning"])


def bic(rss: float, n: int, k: int) -> float:
    """Bayesian information criterion of a Gaussian least-squares fit.

    Parameters
    ----------
    rss : float
        Residual sum of squares.
    n, k : int
        Number of observations and of free parameters.

    Returns
    -------
    float
        n ln(RSS/n) + k ln n.
    """
    return n * np.log(max(rss, 1e-300) / n) + k * np.log(n)


@dataclass(frozen=True)
class Candidate:
    """A model calibrated to the data: the current model or the current model plus one effect."""

    effect: str
    params: dict
    rss: float
    n: int
    k: int            # calibrated parameters
    loo_rmse: float   # leave-one-specimen-out error

    @property
    def rmse(self) -> float:
        """Root-mean-square error of the fit (arcmin)."""
        return float(np.sqrt(self.rss / self.n))


@dataclass
class Ranked:
    """One candidate's row of a ranking: its fit and ΔBIC against the current model."""

    effect: str
    params: dict
    rmse_arcmin: float
    delta_bic: float
    loo_rmse_arcmin: float
    pays: bool
    takes_out: bool | None = None   # takes out the residual's clearest component (None: not judged)


@dataclass
class Verdict:
    """The candidates ranked by ΔBIC and the decision."""

    ranking: list[Ranked]
    missing_effect: str | None          # the paying candidate of lowest BIC, None when none pays
    indistinguishable_from: list[str]   # paying candidates within the tie threshold of it
    text: str

    def decision(self) -> dict:
        """The decision as ``diagnosis.json`` gives it (``missing_effect``, ``indistinguishable_from``, ``text``)."""
        return {"missing_effect": self.missing_effect, "indistinguishable_from": self.indistinguishable_from,
                "text": self.text}


def verdict(baseline: Candidate, candidates: list[Candidate], pay_threshold: float = 10.0,
            tie_threshold: float = 6.0, takes_out: dict[str, bool] | None = None) -> Verdict:
    """Rank candidates by ΔBIC against the baseline and decide.

    A candidate *pays* when ΔBIC ≤ −``pay_threshold`` (10: very strong evidence, Kass &
    Raftery 1995) and its leave-one-out error is below the baseline's. The missing effect
    is the paying candidate of lowest BIC that takes out the residual's clearest component
    (``takes_out``; one that pays by absorbing a share of a residual it cannot reproduce is
    not named); paying candidates within ``tie_threshold`` of it (less than strong evidence
    to prefer it) are reported as indistinguishable.

    Parameters
    ----------
    baseline : Candidate
        The current model.
    candidates : list of Candidate
        The current model plus each candidate effect, calibrated.
    pay_threshold, tie_threshold : float
        ΔBIC a candidate must earn, and the gap below which two paying ones are a tie.
    takes_out : dict, optional
        ``{effect: bool}`` for the paying candidates (default: every candidate does).

    Returns
    -------
    Verdict
        The ranking (lowest ΔBIC first) and the decision.
    """
    b0 = bic(baseline.rss, baseline.n, baseline.k)
    ranking = []
    for c in candidates:
        d = bic(c.rss, c.n, c.k) - b0
        ranking.append(Ranked(c.effect, c.params, c.rmse, float(d), c.loo_rmse,
                              bool(d <= -pay_threshold and c.loo_rmse < baseline.loo_rmse),
                              None if takes_out is None else takes_out.get(c.effect)))
    ranking.sort(key=lambda r: r.delta_bic)
    named = [r for r in ranking if r.pays and r.takes_out is not False]
    if not named:
        return Verdict(ranking, None, [], "no missing effect found")
    best = named[0]
    ties = [r.effect for r in named[1:] if r.delta_bic - best.delta_bic < tie_threshold]
    text = f"{best.effect} is missing" + (f"; the data cannot tell it from {', '.join(ties)}" if ties else "")
    return Verdict(ranking, best.effect, ties, text)
