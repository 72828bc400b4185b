"""What the residual looks like: the baseline model's error split into a few named terms.

The residual is r = D − S, measured minus model (minus the comparison error E of
``hdwf.validation.comparison``), on the diagnosis's comparison points. Each term has a standard
error (se) and is significant beyond ``SIGNIFICANT_Z`` se (docs/validation.md, "The residual's
signature"):

* ``bias``: the mean of r (for Φ/φ data, the dead-band/level term);
* ``slope`` (curves): the least-squares slope of r on torque in r ~ 1 + T + side + loop (side: the
  sign of the last non-zero torque; loop: ±side on unloading/loading branches), so that a play
  or loop error is not read as compliance; also in arcmin at the test torque (the largest |T|);
* ``dead_band`` (curves): per specimen, r at zero torque after loading positive minus after
  loading negative (measured play minus the model's), averaged over specimens;
* ``loop_width`` (curves): sign(T) × (r on the unloading branch − r on the loading branch of the
  same sign, interpolated at the same |T|): the measured loop minus the model's, over all pairs and
  per torque level;
* ``trend_<param>``: slope of the per-specimen mean r on each input (arcmin per µm) and its R²;
* noise: the median stated u against an estimate from the data (``hdwf.validation.noise``).

The dominant term is the significant one largest against its se (statsmodels OLS fits).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np
import pandas as pd
import statsmodels.api as sm

from hdwf import PARAMETER_COLUMNS
from hdwf.validation.comparison import Ranked, branches
from hdwf.validation.noise import NoiseCheck, noise_check, noise_estimate

SIGNIFICANT_Z = 3.0        # a term is significant beyond this many standard errors
FAILS_RATIO = 2.0          # the model "fails" when its RMSE exceeds the noise this many times

_PHRASES = {
    "bias": "a level offset of {v} ± {se} arcmin (measured minus model)",
    "slope": "a compliance error of {v} ± {se} arcmin per N·m ({va} arcmin at the test torque)",
    "dead_band": "a play-width error of {v} ± {se} arcmin at zero torque (measured play minus the model's)",
    "loop_width": "a hysteresis loop of width {v} ± {se} arcmin between loading and unloading branches",
    "trend": "a trend with {p} of {v} ± {se} arcmin per µm ({va} arcmin across the specimens)",
}


@dataclass(frozen=True)
class SignatureTerm:
    """One component of the residual, with its standard error.

    Attributes
    ----------
    name : str
        ``bias``, ``slope``, ``dead_band``, ``loop_width`` or ``trend_<parameter column>``.
    value, se : float
        The estimate and its standard error, in ``unit``.
    unit : str
        ``arcmin``, ``arcmin/(N·m)`` or ``arcmin/µm``.
    value_arcmin, se_arcmin : float
        The same in arcmin (a slope at the test torque, a trend across the specimens' range).
    n : int
        Values it was estimated from (points, specimens or branch pairs).
    unit_note : str
        What it measures, in words.
    r_squared : float, optional
        Trends: the share of the per-specimen variance of the residual it explains.
    """

    name: str
    value: float
    se: float
    unit: str
    value_arcmin: float
    se_arcmin: float
    n: int
    unit_note: str
    r_squared: float | None = None

    @property
    def z(self) -> float:
        """|value| / se (inf for a non-zero value with se 0, NaN when se is unknown)."""
        if not math.isfinite(self.se):
            return float("nan")
        if self.se == 0:
            return float("inf") if self.value != 0 else 0.0
        return abs(self.value) / self.se

    @property
    def significant(self) -> bool:
        """Beyond ``SIGNIFICANT_Z`` standard errors."""
        return bool(self.z > SIGNIFICANT_Z)

    def as_dict(self) -> dict:
        """The term as ``diagnosis.json`` gives it (with ``z`` and ``significant``)."""
        return {**asdict(self), "z": self.z, "significant": self.significant}


@dataclass(frozen=True)
class LoopLevel:
    """The loop width at one |torque| level (measured loop minus the model's, arcmin)."""

    abs_torque_Nm: float
    width_arcmin: float
    se_arcmin: float
    n: int
    significant: bool


@dataclass(frozen=True)
class ResidualSignature:
    """The baseline model's residual, split into named terms, with the noise and a verdict text."""

    form: str
    n_points: int
    n_specimens: int
    rmse_arcmin: float
    test_torque_Nm: float | None
    terms: tuple[SignatureTerm, ...]
    loop_levels: tuple[LoopLevel, ...]
    noise: NoiseCheck
    left_out: dict[str, str] = field(default_factory=dict)   # {term: why it was not computed}
    text: str = ""

    @property
    def rmse_over_noise(self) -> float | None:
        """The RMSE of the residual over the reference noise (None without one)."""
        ref = self.noise.reference_arcmin
        return self.rmse_arcmin / ref if ref else None

    @property
    def dominant(self) -> str | None:
        """The significant term largest against its se (None when no term is significant)."""
        sig = [t for t in self.terms if t.significant]
        return max(sig, key=lambda t: t.z).name if sig else None

    @property
    def clearest_component(self) -> tuple[str, ...]:
        """What a candidate must take out: the significant term along the curve largest against its
        se (a trend with an input only when none stands out: its se counts every point, though the
        specimens alone carry it); a hysteresis loop (``_dominant_phrase``) is two terms."""
        sig = [t for t in self.terms if t.significant]
        pool = [t for t in sig if not t.name.startswith("trend_")] or sig
        if not pool:
            return ()
        dom, loop = max(pool, key=lambda t: t.z), self.term("loop_width")
        if dom.name == "dead_band" and dom.value > 0 and loop is not None and loop.significant and loop.value > 0:
            return ("dead_band", "loop_width")
        return (dom.name,)

    def term(self, name: str) -> SignatureTerm | None:
        """The term called ``name`` (None when it was not computed)."""
        return next((t for t in self.terms if t.name == name), None)

    def to_dict(self) -> dict:
        """The signature as ``diagnosis.json``'s ``signature`` gives it."""
        return {"residual": "measured minus model, D - S (arcmin)", "form": self.form, "n_points": self.n_points,
                "n_specimens": self.n_specimens, "rmse_arcmin": self.rmse_arcmin,
                "test_torque_Nm": self.test_torque_Nm, "significant_z": SIGNIFICANT_Z,
                "terms": [t.as_dict() for t in self.terms],
                "loop_levels": [asdict(lv) for lv in self.loop_levels],
                "noise": {**asdict(self.noise), "reference_arcmin": self.noise.reference_arcmin,
                          "rmse_over_noise": self.rmse_over_noise},
                "dominant": self.dominant, "left_out": dict(self.left_out), "text": self.text}


def _ols(y: np.ndarray, X: np.ndarray, k: int) -> tuple[float, float, object] | None:
    """Coefficient ``k`` of OLS y ~ X and its se (and the fit); None when there are too few values."""
    if len(y) <= X.shape[1] or np.linalg.matrix_rank(X) < X.shape[1]:
        return None
    fit = sm.OLS(y, X).fit()
    return float(fit.params[k]), float(fit.bse[k]), fit


def _mean_se(x: np.ndarray) -> tuple[float, float]:
    """Mean and its standard error (NaN se below two values)."""
    x = np.asarray(x, float)
    return float(x.mean()), float(x.std(ddof=1) / np.sqrt(len(x))) if len(x) > 1 else float("nan")


def _curve_frame(points: pd.DataFrame) -> tuple[pd.DataFrame, float, float]:
    """The curve points in test order with r, branch, ``side`` (sign of the last non-zero torque,
    0 before any) and ``zero`` (at zero torque); the test torque and the zero tolerance (a quarter
    of the median load step)."""
    c = points.sort_values(["specimen_id", "step"], kind="stable").reset_index(drop=True)
    if "branch" not in c:
        c["branch"] = np.concatenate([branches(g["torque_Nm"].to_numpy()) for _, g in
                                      c.groupby("specimen_id", sort=False)])
    T = c["torque_Nm"].to_numpy(float)
    steps = np.abs(c.groupby("specimen_id", sort=False)["torque_Nm"].diff().to_numpy(float))
    steps = steps[np.isfinite(steps) & (steps > 0)]
    tol = 0.25 * float(np.median(steps)) if steps.size else 0.0
    c["r"] = c["D"].to_numpy(float) - c["S"].to_numpy(float)
    c["zero"] = np.abs(T) <= tol
    c["side"] = pd.Series(np.where(c["zero"], np.nan, np.sign(T))).groupby(c["specimen_id"]).ffill().fillna(0.0)
    return c, float(np.abs(T).max()), tol


def _bias(r: np.ndarray, form: str) -> SignatureTerm:
    """The mean residual."""
    v, se = _mean_se(r)
    note = {"curve": "mean of D - S over every point",
            "phi": "mean of D - S over phi and phi': the dead-band/level term",
            "lost_motion": "mean of D - S of the lost motion: the dead-band/level term"}[form]
    return SignatureTerm("bias", v, se, "arcmin", v, se, len(r), note)


def _slope(c: pd.DataFrame, t_test: float) -> SignatureTerm | None:
    """Slope of r on torque, r ~ 1 + T + side + loop (the last of these dropped while collinear)."""
    T, side = c["torque_Nm"].to_numpy(float), c["side"].to_numpy(float)
    loop = side * np.where(c["branch"].str.startswith("unload"), 1.0, -1.0)
    X = np.column_stack([np.ones(len(c)), T, side, loop])
    while X.shape[1] > 2 and np.linalg.matrix_rank(X) < X.shape[1]:
        X = X[:, :-1]
    got = _ols(c["r"].to_numpy(float), X, 1)
    if got is None:
        return None
    b, se, _ = got
    return SignatureTerm("slope", b, se, "arcmin/(N·m)", b * t_test, se * t_test, len(c),
                         f"least-squares slope of D - S on torque (side of the play and branch as further "
                         f"regressors); arcmin: at the test torque {t_test:.4g} N·m")


def _dead_band(c: pd.DataFrame, sigma: float | None) -> SignatureTerm | None:
    """Mean over specimens of r at zero torque after +T minus after -T; se from their spread (or,
    with one specimen, from the noise: sqrt(2) sigma)."""
    z = c[c["zero"] & (c["side"] != 0)]
    per = z.groupby(["specimen_id", "side"])["r"].mean().unstack()
    if 1.0 not in per or -1.0 not in per:
        return None
    d = (per[1.0] - per[-1.0]).dropna().to_numpy(float)
    if d.size == 0:
        return None
    v, se = _mean_se(d)
    if d.size == 1:
        se = math.sqrt(2.0) * sigma if sigma else float("nan")
    return SignatureTerm("dead_band", v, se, "arcmin", v, se, int(d.size),
                         "D - S at zero torque after loading positive minus after loading negative: "
                         "the measured play minus the model's")


def _loop_pairs(c: pd.DataFrame, tol: float) -> pd.DataFrame:
    """Per unloading point at non-zero torque: its |T| and the loop width there, sign(T) times
    (r on the unloading branch minus r on the loading branch of the same sign at that |T|)."""
    rows = []
    for _, g in c[~c["zero"]].groupby("specimen_id", sort=False):
        for sgn, tag in ((1.0, "+"), (-1.0, "-")):
            load, unload = g[g["branch"] == "load" + tag], g[g["branch"] == "unload" + tag]
            if load.empty or unload.empty:
                continue
            a_l = np.abs(load["torque_Nm"].to_numpy(float))
            order = np.argsort(a_l)
            a_l, r_l = a_l[order], load["r"].to_numpy(float)[order]
            for a, r in zip(np.abs(unload["torque_Nm"].to_numpy(float)), unload["r"].to_numpy(float)):
                if a_l[0] - tol <= a <= a_l[-1] + tol:
                    rows.append((a, sgn * (r - float(np.interp(a, a_l, r_l)))))
    return pd.DataFrame(rows, columns=["abs_torque", "width"])


def _loop(c: pd.DataFrame, tol: float) -> tuple[SignatureTerm | None, tuple[LoopLevel, ...]]:
    """The loop width over all branch pairs, and per |torque| level (levels closer than the
    zero tolerance are one)."""
    pairs = _loop_pairs(c, tol).sort_values("abs_torque", kind="stable")
    if pairs.empty:
        return None, ()
    level = np.concatenate([[0], np.cumsum(np.diff(pairs["abs_torque"].to_numpy()) > tol)])
    levels = []
    for _, g in pairs.groupby(level):
        v, se = _mean_se(g["width"].to_numpy())
        levels.append(LoopLevel(float(g["abs_torque"].mean()), v, se, len(g),
                                bool(math.isfinite(se) and abs(v) > SIGNIFICANT_Z * se)))
    v, se = _mean_se(pairs["width"].to_numpy())
    term = SignatureTerm("loop_width", v, se, "arcmin", v, se, len(pairs),
                         "at equal |torque|: D - S on the unloading branch minus on the loading branch, "
                         "in the direction of the torque: the measured loop minus the model's")
    return term, tuple(levels)


def _trends(points: pd.DataFrame, r: np.ndarray) -> list[SignatureTerm]:
    """Slope of the per-specimen mean residual on each input (arcmin per µm), with R²."""
    cols = [p for p in PARAMETER_COLUMNS if p in points]
    spec = points.assign(r=r).groupby("specimen_id", sort=False).agg(r=("r", "mean"), **{p: (p, "first") for p in cols})
    out = []
    for p in cols:
        x = spec[p].to_numpy(float) * 1000.0           # mm -> µm
        if len(spec) < 3 or np.ptp(x) == 0:
            continue
        got = _ols(spec["r"].to_numpy(float), sm.add_constant(x), 1)
        if got is None:
            continue
        b, se, fit = got
        span = float(np.ptp(x))
        out.append(SignatureTerm(f"trend_{p}", b, se, "arcmin/µm", b * span, se * span, len(spec),
                                 f"slope of the per-specimen mean D - S on {p}; arcmin: across its range "
                                 f"{span:.4g} µm", r_squared=float(fit.rsquared)))
    return out


def residual_signature(points: pd.DataFrame, form: str) -> ResidualSignature:
    """The signature of the residual D − S on a diagnosis's comparison points.

    Parameters
    ----------
    points : pandas.DataFrame
        Comparison points (``hdwf.validation.comparison.comparison_points``): ``specimen_id``,
        ``D``, ``S``, ``u_D``, the parameter columns and, for curves, ``step``, ``torque_Nm`` and
        (else derived from the step order) ``branch``.
    form : str
        ``curve``, ``phi`` or ``lost_motion``.

    Returns
    -------
    ResidualSignature
        Terms, loop per torque level, noise check; its text without candidates (see ``with_verdict``).
    """
    r = points["D"].to_numpy(float) - points["S"].to_numpy(float)
    is_curve = form == "curve" and "torque_Nm" in points and "step" in points
    c, t_test, tol = _curve_frame(points) if is_curve else (None, None, 0.0)
    noise = noise_check(points["u_D"].to_numpy(float) if "u_D" in points else np.full(len(r), np.nan),
                        *noise_estimate(points, c, r))
    terms, levels, left_out = [_bias(r, form)], (), {}
    if c is not None:
        loop, levels = _loop(c, tol)
        for name, t in (("slope", _slope(c, t_test)), ("dead_band", _dead_band(c, noise.reference_arcmin)),
                        ("loop_width", loop)):
            if t is None:
                left_out[name] = "too few points of the kind it needs"
            else:
                terms.append(t)
    else:
        left_out.update({k: f"needs curve data (this is {form})" for k in ("slope", "dead_band", "loop_width")})
    trends = _trends(points, r)
    terms += trends
    if not trends:
        left_out["trends"] = "needs three specimens or more with varying inputs"
    sig = ResidualSignature(form, len(r), int(points["specimen_id"].nunique()), float(np.sqrt(np.mean(r ** 2))),
                            t_test, tuple(terms), levels, noise, left_out)
    return replace(sig, text=describe(sig))


def _dominant_phrase(sig: ResidualSignature, dom: SignatureTerm) -> str:
    """The dominant term in words. A wider gap at zero torque whose branches stay apart under load
    too is a hysteresis loop, not play: a dead band closes as soon as the torque is non-zero."""
    loop = sig.term("loop_width")
    if sig.clearest_component == ("dead_band", "loop_width") and dom.name == "dead_band":
        return (f"a hysteresis loop {_phrase(dom, bare=True)} arcmin wide at zero torque whose branches stay "
                f"{_phrase(loop, bare=True)} arcmin apart under load (play would close under load)")
    return _phrase(dom)


def _phrase(t: SignatureTerm, bare: bool = False) -> str:
    """A term in words, for the verdict: the value to the decimals of its se's two leading digits."""
    key = "trend" if t.name.startswith("trend_") else t.name
    dec = min(max(1 - math.floor(math.log10(t.se)), 0), 8) if math.isfinite(t.se) and t.se > 0 else 4
    if bare:  # value ± se only
        return f"{t.value:.{dec}f} ± {t.se:.2g}"
    return _PHRASES[key].format(v=f"{t.value:.{dec}f}", se=f"{t.se:.2g}", va=f"{t.value_arcmin:.3g}",
                                p=t.name.removeprefix("trend_"))


def describe(sig: ResidualSignature, found: list[str] | None = None, final_rmse_arcmin: float | None = None,
             closest: Ranked | None = None, closest_at_bound: bool = False,
             current_rmse_arcmin: float | None = None) -> str:
    """The signature in one sentence: how badly the model fails, the residual's dominant term,
    and what the diagnosis made of it.

    Parameters
    ----------
    sig : ResidualSignature
        The baseline residual's signature.
    found : list of str, optional
        The effects the diagnosis found, in order.
    final_rmse_arcmin : float, optional
        The RMSE with them switched on, as the calibration tables give it (the ladder re-solves it).
    closest : Ranked, optional
        The best-ranked candidate of round 1, when none was found.
    closest_at_bound : bool
        Its estimate sits at a bound of its range.
    current_rmse_arcmin : float, optional
        The RMSE of the model round 1 started from (default: the signature's).

    Returns
    -------
    str
        e.g. "the model fails (RMSE 15× the noise); the residual's clearest component is ...".
    """
    ratio = sig.rmse_over_noise
    if ratio is None:
        parts = [f"the model's RMSE is {sig.rmse_arcmin:.3g} arcmin (no noise to compare it with)"]
    else:
        word = "fails" if ratio > FAILS_RATIO else f"fits to within {FAILS_RATIO:g}× the noise"
        parts = [f"the model {word} (RMSE {ratio:.3g}× the noise)"]
    dom = sig.term(sig.dominant) if sig.dominant else None
    parts.append(f"the residual's clearest component is {_dominant_phrase(sig, dom)}" if dom else
                 f"no component of the residual stands out from the noise (none beyond {SIGNIFICANT_Z:g} se)")
    if found:
        end = (f" (RMSE {sig.rmse_arcmin:.4g} → {final_rmse_arcmin:.4g} arcmin on the calibration tables)"
               if final_rmse_arcmin is not None else "")
        parts.append(f"{', then '.join(found)} explained it{end}")
    elif closest is not None:
        where = " at its bound" if closest_at_bound else ""
        cur = sig.rmse_arcmin if current_rmse_arcmin is None else current_rmse_arcmin
        parts.append(f"no candidate reproduces it (the closest, {closest.effect}{where}, gives RMSE "
                     f"{closest.rmse_arcmin:.4g} arcmin against {cur:.4g}, ΔBIC {closest.delta_bic:.1f})")
    return "; ".join(parts)


def with_verdict(sig: ResidualSignature, found: list[str], final_rmse_arcmin: float, closest: Ranked | None,
                 closest_at_bound: bool, current_rmse_arcmin: float | None = None) -> ResidualSignature:
    """The signature with ``describe``'s text for what the diagnosis found (arguments as there)."""
    return replace(sig, text=describe(sig, found, final_rmse_arcmin, closest, closest_at_bound, current_rmse_arcmin))
