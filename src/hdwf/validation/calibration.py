"""Calibration of effects on measurements: responses, least squares, re-solves, leave-one-out.

* An effect's prediction at parameter t (its ``transform``: t = 0 is "off") is the cubic
  spline through the tabulated values, point by point (``Response``, ``responses``).
* Effects act together by superposition of their changes (exact when one of two acts in
  series at the output, an approximation otherwise, which the ladder's actual solves check);
  their parameters are calibrated jointly by bounded least squares
  (``scipy.optimize.least_squares``), with covariance s^2 (J^T J)^-1 (``calibrate``, ``Fit``).
* Once an effect is found it can be solved at three values around its estimate and its
  prediction there taken from those solves (``anchored_responses``, ``refine_fit``): a spline
  through the grid is off by up to a few hundredths of an arcmin where tooth pairs close
  between two grid values, enough to tip two look-alike candidates with thousands of readings.
* ``loo_rmse``: the leave-one-specimen-out error (recalibrated without that specimen).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import Callable

import numpy as np
import pandas as pd
from scipy.interpolate import make_interp_spline
from scipy.optimize import least_squares

from hdwf.validation.effects import get as get_effect
from hdwf.validation.observations import predict
from hdwf.validation.variants import variant_key

# Recalibration on actual solves: around an estimate t the response is solved at t - h, t and
# t + h, h this share of the table's grid spacing; at most this many solves per effect.
ANCHOR_HALF_WIDTH = 0.1
ANCHOR_SOLVES = 4


@dataclass
class Response:
    """The prediction of every observation as a function of one effect's parameter t."""

    effect: str
    param: str
    t: np.ndarray          # sorted grid in the transformed parameter (includes 0 = off)
    S: np.ndarray          # (len(t), n_obs)
    t_bounds: tuple[float, float]
    off: np.ndarray | None = None   # the prediction with the effect off (default: the row at t = 0)
    # actual solves near an estimate: (their three t, their predictions), see anchored_responses
    anchor: tuple[np.ndarray, np.ndarray] | None = None

    def __post_init__(self):
        k = min(3, len(self.t) - 1)
        self._spline = make_interp_spline(self.t, self.S, k=k, axis=0)
        if self.off is None:
            self.off = self.S[int(np.argmin(np.abs(self.t)))]
        if self.anchor is not None:
            ta, Sa = self.anchor
            self._local = make_interp_spline(ta, Sa, k=2, axis=0)
            self._shift = (Sa[0] - self._spline(ta[0]), Sa[-1] - self._spline(ta[-1]))
            # the grid values next to the solved interval, where the shift has faded to zero
            below, above = self.t[self.t < ta[0]], self.t[self.t > ta[-1]]
            self._fade_to = (below.max() if below.size else None, above.min() if above.size else None)

    def change(self, t: float) -> np.ndarray:
        """Prediction at t minus the prediction with the effect off."""
        t = float(t)
        if self.anchor is None:
            return self._spline(t) - self.off
        ta = self.anchor[0]
        if ta[0] <= t <= ta[-1]:        # the quadratic through the actual solves
            return self._local(t) - self.off
        # outside: the spline, shifted to meet them (continuous at both ends), the shift
        # fading linearly to zero at the next grid value (the spline is exact there)
        side = 0 if t < ta[0] else 1
        edge, grid = ta[0 if side == 0 else -1], self._fade_to[side]
        w = 1.0 if grid is None else min(max((t - grid) / (edge - grid), 0.0), 1.0)
        return self._spline(t) + w * self._shift[side] - self.off

    def value(self, t: float) -> float:
        """The parameter's value at t."""
        return get_effect(self.effect).param(self.param).from_t(t)


def responses(table: pd.DataFrame, obs: pd.DataFrame, fixed: dict, candidates: list[str],
              notes: dict | None = None) -> dict[str, Response]:
    """Each candidate's tabulated response.

    A grid value whose solve failed for any specimen is dropped and the calibration range
    shrinks to the values that solved; a candidate left with fewer than two values is not
    calibrated at all.

    Parameters
    ----------
    table : pandas.DataFrame
        The campaign's tables (``hdwf.validation.variants.plan_variants``, solved).
    obs : pandas.DataFrame
        Observations (``hdwf.validation.observations.observation_frame``).
    fixed : dict
        The campaign model's effects.
    candidates : list of str
        The effects whose grids the tables hold.
    notes : dict, optional
        Filled with ``{effect: note}`` for dropped values and uncalibrated candidates.

    Returns
    -------
    dict
        ``{effect: Response}`` of the candidates that can be calibrated.
    """
    S0 = predict(table, obs, variant_key(fixed))
    out = {}
    for name in candidates:
        p = get_effect(name).parameters[0]
        ts, Ss, dropped = [0.0], [S0], []
        for v in p.grid():
            key = variant_key({**fixed, name: {p.name: v}})
            S = predict(table, obs, key)
            if np.isfinite(S).all():
                ts.append(p.to_t(v))
                Ss.append(S)
            else:
                rows = table[table["variant"] == key]
                dropped.append(f"{v:g} ({rows.loc[rows['status'] != 'ok', 'specimen_id'].nunique()} "
                               "specimens)")
        failed = f"solve failed at {p.name} = {', '.join(dropped)}"
        if notes is not None and dropped:
            notes[name] = f"{failed}; calibrated over the values that solved"
        if len(ts) < 2:
            if notes is not None:
                notes[name] = f"{failed}: no grid value solved for every specimen; not calibrated"
            continue
        order = np.argsort(ts)
        lo, hi = p.t_bounds
        tb = (max(lo, min(ts)), min(hi, max(ts)))
        out[name] = Response(name, p.name, np.asarray(ts)[order], np.asarray(Ss)[order], tb)
    return out


@dataclass
class CalibrationData:
    """What a calibration fits: the measured values, the campaign model's prediction of them
    and each effect's response (``refine_fit`` replaces a response by its anchored one)."""

    D: np.ndarray
    S0: np.ndarray
    resp: dict[str, Response]

    def model(self, effects: list[str], t) -> np.ndarray:
        """The prediction with ``effects`` switched on at ``t``: their changes added to ``S0``."""
        S = self.S0.copy()
        for e, tk in zip(effects, t):
            S = S + self.resp[e].change(tk)
        return S


@dataclass
class Fit:
    """Effects calibrated together: their t, its covariance, the prediction and its residual."""

    effects: list[str]
    t: np.ndarray
    cov_t: np.ndarray
    S: np.ndarray          # prediction at the calibrated values
    rss: float
    n: int

    def params(self, resp: dict[str, Response]) -> dict[str, dict[str, float]]:
        """Calibrated values; an effect calibrated to "off" (t ~ 0) gets its off value."""
        out = {}
        for e, t in zip(self.effects, self.t):
            lo, hi = resp[e].t_bounds
            off = abs(t) <= 1e-6 * max(abs(lo), abs(hi))
            out[e] = {resp[e].param: float(get_effect(e).off.get(resp[e].param, 0.0)) if off
                      else float(resp[e].value(t))}
        return out

    def param_sd(self, resp: dict[str, Response]) -> dict[str, float]:
        """Standard uncertainty of each calibrated parameter, in its own unit."""
        out = {}
        for k, (e, t) in enumerate(zip(self.effects, self.t)):
            sd_t = math.sqrt(max(self.cov_t[k, k], 0.0))
            p = get_effect(e).param(resp[e].param)
            out[e] = p.sd_from_t(t, sd_t)
        return out


def calibrate(data: CalibrationData, effects: list[str], start: list[float] | None = None,
              mask: np.ndarray | None = None) -> Fit:
    """Least squares on the measurements over the parameters of ``effects`` (jointly).

    Parameters
    ----------
    data : CalibrationData
        Measured values, campaign model and responses.
    effects : list of str
        The effects switched on, each with a response in ``data.resp``.
    start : list of float, optional
        Start values of the first effects' t; each further effect starts at the best of a
        scan of its range (the fit is not convex in general).
    mask : numpy.ndarray of bool, optional
        The observations to fit (default: all).

    Returns
    -------
    Fit
        The calibrated t, their covariance s^2 (J^T J)^-1 and the prediction at them.
    """
    D = data.D
    m = np.ones(len(D), bool) if mask is None else mask
    lo = np.array([data.resp[e].t_bounds[0] for e in effects])
    hi = np.array([data.resp[e].t_bounds[1] for e in effects])
    x0 = list(start or [])
    # dead bands and friction change which teeth carry the load, hence the scan
    for k in range(len(x0), len(effects)):
        grid = np.linspace(lo[k], hi[k], 41)
        rss = [np.sum((D[m] - data.model(effects, x0 + [g] + [0.0] * (len(effects) - k - 1))[m]) ** 2)
               for g in grid]
        x0.append(float(grid[int(np.argmin(rss))]))
    scale = np.maximum(hi - lo, 1e-300)

    def res(z):
        return (data.model(effects, lo + z * scale) - D)[m]

    z0 = np.clip((np.asarray(x0) - lo) / scale, 0, 1)
    sol = least_squares(res, z0, bounds=(0.0, 1.0), x_scale=1.0, diff_step=1e-4, method="trf")
    t = lo + sol.x * scale
    S = data.model(effects, t)
    r = (S - D)[m]
    n = int(m.sum())
    J = sol.jac / scale[None, :]
    s2 = float(r @ r) / max(n - len(effects), 1)
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.full((len(effects), len(effects)), np.inf)
    return Fit(list(effects), t, cov, S, float(r @ r), n)


def loo_rmse(data: CalibrationData, effects: list[str], fit: Fit, specimen: np.ndarray) -> float:
    """Leave one specimen out: calibrate on the others, predict the one left out.

    Parameters
    ----------
    data : CalibrationData
        Measured values, campaign model and responses.
    effects : list of str
        The effects switched on (none: the campaign model's error).
    fit : Fit
        The calibration on every specimen (its t start each recalibration).
    specimen : numpy.ndarray
        The specimen of each observation.

    Returns
    -------
    float
        RMS of the left-out predictions' errors (arcmin).
    """
    D = data.D
    if not effects:
        return float(np.sqrt(np.mean((data.S0 - D) ** 2)))
    err = np.zeros(len(D))
    for sid in pd.unique(specimen):
        out = specimen == sid
        f = calibrate(data, effects, start=list(fit.t), mask=~out)
        err[out] = (f.S - D)[out]
    return float(np.sqrt(np.mean(err ** 2)))


# ------------------------------------------------------------------ re-solves near an estimate

@dataclass(frozen=True)
class Resolver:
    """Actual solves of the model near an estimate.

    Attributes
    ----------
    solve : callable
        ``solve(variants)``: the table rows of every specimen for those variants
        (``hdwf.validation.variants.specimen_solver``).
    obs : pandas.DataFrame
        The observations to predict.
    fixed : dict
        The campaign model's effects.
    table_resp : dict
        Each effect's response from the tables, on which an anchored one is built.
    """

    solve: Callable[[list[dict]], pd.DataFrame]
    obs: pd.DataFrame
    fixed: dict
    table_resp: dict[str, Response]


@dataclass(frozen=True)
class Refinement:
    """Where an effect was re-solved (``status`` anchored) or why its response was kept
    (failed, unsettled: ``reason``); before which round (None: for the final model)."""

    status: str
    before_round: int | None = None
    param: str | None = None
    solved_at: list[float] | None = None
    solves: int | None = None
    reason: str | None = None

    def as_dict(self) -> dict:
        """The entry as ``diagnosis.json`` gives it (fields that apply only)."""
        return {k: v for k, v in asdict(self).items() if v is not None}


def anchor_points(table_resp: Response, t_hat: float) -> tuple[np.ndarray, list[float]] | None:
    """The three t (and parameter values) to solve around an estimate.

    They are t_hat - h, t_hat, t_hat + h, h = ``ANCHOR_HALF_WIDTH`` of the table's grid
    spacing, moved inside the range of the parameter's values (for a reciprocal transform
    t = 0, "off", is not a value).

    Parameters
    ----------
    table_resp : Response
        The effect's response from the tables.
    t_hat : float
        The estimate.

    Returns
    -------
    tuple or None
        ``(t, values)``; None when the range of values is narrower than 2h.
    """
    p = get_effect(table_resp.effect).param(table_resp.param)
    lo, hi = p.t_bounds
    h = ANCHOR_HALF_WIDTH * (hi - lo) / p.grid_points
    vlo, vhi = sorted((p.to_t(p.lower), p.to_t(p.upper)))
    if vhi - vlo < 2 * h:
        return None
    centre = min(max(float(t_hat), vlo + h), vhi - h)
    values = [p.clip(p.from_t(t)) for t in (centre - h, centre, centre + h)]
    ts = np.array([p.to_t(v) for v in values])
    return (ts, values) if np.all(np.diff(ts) > 0) else None


def anchored_responses(resolver: Resolver, t_hat: dict[str, float]) -> dict[str, Response | str]:
    """Each effect's table response anchored to actual solves at its ``anchor_points``.

    Between the three, the quadratic through them; outside, the table's spline shifted to meet
    them, the shift fading to zero at the next grid value (where the spline is exact anyway).
    One ``solve`` call for all effects (one mesh per specimen).

    Parameters
    ----------
    resolver : Resolver
        The solve, the observations, the campaign model and the tables' responses.
    t_hat : dict
        ``{effect: estimate of t}``.

    Returns
    -------
    dict
        ``{effect: Response}``, or the reason (str) where no anchored response could be built.
    """
    out: dict[str, Response | str] = {}
    plan = {}
    for e, t in t_hat.items():
        pts = anchor_points(resolver.table_resp[e], t)
        if pts is None:
            out[e] = "its range is too narrow to solve around the estimate"
        else:
            pname = resolver.table_resp[e].param
            plan[e] = (pts[0], [{**resolver.fixed, e: {pname: v}} for v in pts[1]])
    if not plan:
        return out
    try:
        tab = resolver.solve([v for _, vs in plan.values() for v in vs])
    except Exception as exc:          # a crashed solve must not lose the diagnosis
        return {**out, **{e: f"the solve failed ({type(exc).__name__}: {exc})" for e in plan}}
    for e, (ts, variants) in plan.items():
        S = np.array([predict(tab, resolver.obs, variant_key(v)) for v in variants])
        if not np.isfinite(S).all():
            bad = tab.loc[tab["status"] != "ok"]
            out[e] = "the solve failed" + (
                f" ({bad['specimen_id'].iloc[0]}, {bad['variant'].iloc[0]}: {bad['status'].iloc[0]})"
                if len(bad) else "")
            continue
        r = resolver.table_resp[e]
        out[e] = Response(r.effect, r.param, r.t, r.S, r.t_bounds, off=r.off, anchor=(ts, S))
    return out


def _stale(data: CalibrationData, fit: Fit, resolver: Resolver, done: set) -> dict[str, float]:
    """The effects to (re-)anchor: not in series, not given up on, and either never anchored or
    estimated outside their solved interval (unless pinned where the last anchor was, a bound)."""
    stale = {}
    for k, e in enumerate(fit.effects):
        if get_effect(e).series or e in done:
            continue
        a, t = data.resp[e].anchor, fit.t[k]
        if a is not None:
            pts = anchor_points(resolver.table_resp[e], t)
            if a[0][0] <= t <= a[0][-1] or (pts is not None and np.array_equal(pts[0], a[0])):
                continue
        stale[e] = t
    return stale


def refine_fit(data: CalibrationData, fit: Fit, resolver: Resolver, log: dict[str, Refinement],
               before_round: int | None) -> Fit:
    """Recalibrate switched-on effects on actual solves around their estimates.

    The response of every effect of ``fit`` that needs a contact solve is anchored to actual
    solves around its calibrated value (``anchored_responses``; ``data.resp`` is updated in
    place) and the effects recalibrated, until no estimate leaves its solved interval. Series
    effects are exact in the table (their twist adds to the solved one) and are not anchored.

    Parameters
    ----------
    data : CalibrationData
        Measured values, campaign model and responses.
    fit : Fit
        The calibration to refine.
    resolver : Resolver
        The solve, the observations, the campaign model and the tables' responses.
    log : dict
        ``{effect: Refinement}``: where it was solved, or why the table (or the last anchor)
        was kept; updated in place.
    before_round : int or None
        The search round the refinement precedes, None for the final model (for the log).

    Returns
    -------
    Fit
        The recalibrated fit.
    """
    on, done = fit.effects, set()
    for n_solve in range(1, ANCHOR_SOLVES + 2):
        stale = _stale(data, fit, resolver, done)
        if not stale:
            return fit
        if n_solve > ANCHOR_SOLVES:
            for e in stale:
                # (an effect the final pass found inside its solves at first has no entry yet)
                log[e] = replace(log.get(e, Refinement("unsettled", before_round)), status="unsettled",
                                 reason=f"the estimate still left its solved interval after {ANCHOR_SOLVES} "
                                        "solves; the last anchored response is used")
            return fit
        changed = False
        for e, r in anchored_responses(resolver, stale).items():
            if isinstance(r, str):
                done.add(e)
                kept = "the last anchored response" if data.resp[e].anchor is not None else "the table's response"
                log[e] = replace(log.get(e, Refinement("failed")), status="failed", reason=f"{r}; {kept} is used")
                continue
            data.resp[e], changed = r, True
            log[e] = Refinement("anchored", before_round, r.param, [r.value(t) for t in r.anchor[0]], n_solve)
        if changed:
            fit = calibrate(data, on, start=list(fit.t))
    return fit
