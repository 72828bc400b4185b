"""Which physical effect is the model missing? Calibrate every candidate, rank, decide.

Inputs: checked measurements (``hdwf.validation.measurements``) and the per-specimen tables of the FE
model (``hdwf.validation.campaign``): the campaign's model and, for every candidate effect, the model
with that effect at each value of its parameter's grid.

Method (hand-written around scipy/statsmodels; see docs/validation.md):

* an effect's prediction at parameter t (its ``transform``: t = 0 is "off") is the cubic
  spline through the tabulated values, point by point; once an effect is found (and a further
  round follows) it is solved at three values around its estimate and the prediction there
  comes from those solves (``anchored_responses``, when ``diagnose`` is given a ``solve``);
* effects found earlier stay on; a new candidate is added by superposition of its change
  (exact when one of the two acts in series at the output, an approximation otherwise,
  which the ladder's actual solves check) and all switched-on parameters are calibrated
  together by bounded least squares (``scipy.optimize.least_squares``), with covariance
  s^2 (J^T J)^-1;
* evidence: ΔBIC against the model without the candidate, the leave-one-specimen-out error
  (recalibrated without that specimen), and how well the change the effect makes lines up
  with the residual it should explain (cosine: 1 = the same pattern);
* verdict (``hdwf.validation.comparison.verdict``): a candidate pays when ΔBIC <= -10 and its
  leave-one-out error beats the current model's; paying candidates within ΔBIC 6 of the
  best are reported as indistinguishable; none paying -> "no missing effect found";
* greedy: the winner is switched on and the search repeats for the next effect;
* what the data could see (``detectability``): each candidate at its realistic value changes
  the predictions by a vector Δ; against the noise σ (stated, or else the final model's
  residual, an upper bound) it would be found when the ΔBIC it earns,
  -n ln(1 + |Δ|²/(n σ²)) + ln n, clears the pay threshold, and its parameter would come out
  with relative standard deviation σ/|Δ| in t (linearised, other effects held; for a value
  tabulated as value^-p that is σ/(p|Δ|) of the value).  A "no missing
  effect found" therefore says which candidates this data could not have seen at all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.interpolate import make_interp_spline
from scipy.optimize import least_squares

from hdwf.validation.campaign import mean_lost_motion, variant_key
from hdwf.validation.effects import get as get_effect
from hdwf.validation.comparison import Candidate, bic, comparison_points, residual_tests, summarise, verdict


# ------------------------------------------------------------------ observations

def observation_frame(meas) -> pd.DataFrame:
    """The measured values as one column ``D`` with their keys (specimen_id [, step]) and
    ``quantity`` (twist, phi_plus, phi_minus or lost_motion), and ``u_D`` when given."""
    d = meas.data
    if meas.form == "curve":
        out = d[["specimen_id", "step", "torque_Nm", "twist_arcmin"]].rename(columns={"twist_arcmin": "D"})
        out["quantity"] = "twist"
        out["u_D"] = d["u_twist_arcmin"].to_numpy(float) if "u_twist_arcmin" in d else np.nan
    elif meas.form == "phi":
        parts = []
        for q in ("phi_plus", "phi_minus"):
            part = d[["specimen_id"]].copy()
            part["D"] = d[f"{q}_arcmin"].to_numpy(float)
            part["quantity"] = q
            part["u_D"] = d["u_arcmin"].to_numpy(float) if "u_arcmin" in d else np.nan
            parts.append(part)
        out = pd.concat(parts, ignore_index=True)
    else:
        out = d[["specimen_id"]].copy()
        out["D"] = d["lost_motion_arcmin"].to_numpy(float)
        out["quantity"] = "lost_motion"
        out["u_D"] = d["u_arcmin"].to_numpy(float) if "u_arcmin" in d else np.nan
    return out.reset_index(drop=True)


def predict(table: pd.DataFrame, obs: pd.DataFrame, variant: str) -> np.ndarray:
    """The model's value of every observation for one variant (NaN where its solve failed)."""
    t = table[table["variant"] == variant]
    if t.empty:
        raise KeyError(f"variant {variant!r} is not in the table")
    out = np.full(len(obs), np.nan)
    curves = {sid: g.sort_values("step") for sid, g in t.groupby("specimen_id", sort=False)}
    for i, (sid, q) in enumerate(zip(obs["specimen_id"], obs["quantity"])):
        g = curves.get(sid)
        if g is None:
            raise KeyError(f"specimen {sid!r} has no solve for variant {variant!r}")
        tw = g["twist_arcmin"].to_numpy(float)
        T = g["torque_Nm"].to_numpy(float)
        if not np.isfinite(tw).all():        # this variant's solve failed for this specimen
            continue
        if q == "twist":
            hit = tw[g["step"].to_numpy() == obs["step"].iloc[i]]
            if hit.size == 0:
                raise ValueError(f"specimen {sid!r}: measured step {obs['step'].iloc[i]} is not a step of the "
                                 f"model's test ({len(tw)} steps); set the campaign's steps_per_ramp to match")
            out[i] = hit[0]
        else:
            kp, km = int(np.nanargmax(T)), int(np.nanargmin(T))
            phi_p, phi_m = tw[kp], -tw[km]
            out[i] = {"phi_plus": phi_p, "phi_minus": phi_m, "lost_motion": phi_p + phi_m}[q]
    return out


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
        return get_effect(self.effect).param(self.param).from_t(t)


def responses(table: pd.DataFrame, obs: pd.DataFrame, fixed: dict, candidates: list[str],
              notes: dict | None = None) -> dict[str, Response]:
    """Each candidate's tabulated response. A grid value whose solve failed for any specimen
    is dropped and the calibration range shrinks to the values that solved (``notes``
    records it); a candidate left with fewer than two values is not calibrated at all."""
    base = variant_key(fixed)
    S0 = predict(table, obs, base)
    out = {}
    for name in candidates:
        eff = get_effect(name)
        p = eff.parameters[0]
        ts, Ss, dropped = [0.0], [S0], []
        for v in p.grid():
            key = variant_key({**fixed, name: {p.name: v}})
            S = predict(table, obs, key)
            if np.isfinite(S).all():
                ts.append(p.to_t(v))
                Ss.append(S)
            else:
                dropped.append(v)
        if notes is not None and dropped:
            notes[name] = (f"solve failed at {p.name} = {', '.join(f'{v:g}' for v in dropped)}; "
                           "calibrated over the values that solved")
        if len(ts) < 2:
            if notes is not None:
                notes[name] = f"every grid solve failed; not calibrated"
            continue
        order = np.argsort(ts)
        lo, hi = p.t_bounds
        tb = (max(lo, min(ts)), min(hi, max(ts)))
        out[name] = Response(name, p.name, np.asarray(ts)[order], np.asarray(Ss)[order], tb)
    return out


# ------------------------------------------------------------------ calibration

@dataclass
class Fit:
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


def _model(S0, resp, effects, t):
    S = S0.copy()
    for e, tk in zip(effects, t):
        S = S + resp[e].change(tk)
    return S


def calibrate(D: np.ndarray, S0: np.ndarray, resp: dict[str, Response], effects: list[str],
              start: list[float] | None = None, mask: np.ndarray | None = None) -> Fit:
    """Least squares on the measurements over the parameters of ``effects`` (jointly)."""
    m = np.ones(len(D), bool) if mask is None else mask
    lo = np.array([resp[e].t_bounds[0] for e in effects])
    hi = np.array([resp[e].t_bounds[1] for e in effects])
    if start is None:
        start = []
    x0 = list(start)
    # a new effect starts at the best point of a scan of its range (the fit is not convex
    # in general: dead bands and friction change which teeth carry the load)
    for k in range(len(x0), len(effects)):
        grid = np.linspace(lo[k], hi[k], 41)
        rss = [np.sum((D[m] - _model(S0, resp, effects, x0 + [g] + [0.0] * (len(effects) - k - 1))[m]) ** 2)
               for g in grid]
        x0.append(float(grid[int(np.argmin(rss))]))
    scale = np.maximum(hi - lo, 1e-300)

    def res(z):
        return (_model(S0, resp, effects, lo + z * scale) - D)[m]

    z0 = np.clip((np.asarray(x0) - lo) / scale, 0, 1)
    sol = least_squares(res, z0, bounds=(0.0, 1.0), x_scale=1.0, diff_step=1e-4, method="trf")
    t = lo + sol.x * scale
    S = _model(S0, resp, effects, t)
    r = (S - D)[m]
    n = int(m.sum())
    J = sol.jac / scale[None, :]
    s2 = float(r @ r) / max(n - len(effects), 1)
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.full((len(effects), len(effects)), np.inf)
    return Fit(list(effects), t, cov, S, float(r @ r), n)


# Recalibration on actual solves: around an estimate t the response is solved at t - h, t and
# t + h, h this share of the table's grid spacing; at most this many solves per effect.
ANCHOR_HALF_WIDTH = 0.1
ANCHOR_SOLVES = 4


def anchor_points(table_resp: Response, t_hat: float) -> tuple[np.ndarray, list[float]] | None:
    """The three t (and parameter values) to solve around ``t_hat``: t_hat - h, t_hat, t_hat + h,
    h = ``ANCHOR_HALF_WIDTH`` of the table's grid spacing, moved inside the range of the
    parameter's values (for a reciprocal transform t = 0, "off", is not a value); None when
    that range is narrower than 2h."""
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


def anchored_responses(table_resp: dict[str, Response], t_hat: dict[str, float], solve, obs: pd.DataFrame,
                       fixed: dict) -> dict[str, Response | str]:
    """Each effect's table response anchored to actual solves at its ``anchor_points``: between
    the three, the quadratic through them; outside, the table's spline shifted to meet them,
    the shift fading to zero at the next grid value (where the spline is exact anyway).
    One ``solve`` call for all effects (one mesh per specimen); an effect whose solve failed
    gets the reason instead of a response.

    Why: a spline through the table's grid is off by up to a few hundredths of an arcmin where
    tooth pairs close between two grid values (thermal near zero clearance,
    docs/validation.md); with thousands of readings that is enough to tip two look-alike
    candidates in the next round. ``solve(variants)`` returns the table rows of every
    specimen for those variants."""
    out: dict[str, Response | str] = {}
    plan = {}
    for e, t in t_hat.items():
        pts = anchor_points(table_resp[e], t)
        if pts is None:
            out[e] = "its range is too narrow to solve around the estimate"
        else:
            pname = table_resp[e].param
            plan[e] = (pts[0], [{**fixed, e: {pname: v}} for v in pts[1]])
    if not plan:
        return out
    try:
        tab = solve([v for _, vs in plan.values() for v in vs])
    except Exception as exc:          # a crashed solve must not lose the diagnosis
        return {**out, **{e: f"the solve failed ({type(exc).__name__}: {exc})" for e in plan}}
    for e, (ts, variants) in plan.items():
        S = np.array([predict(tab, obs, variant_key(v)) for v in variants])
        if not np.isfinite(S).all():
            bad = sorted(set(tab.loc[tab["status"] != "ok", "status"]))
            out[e] = "the solve failed" + (f" ({bad[0]})" if bad else "")
            continue
        r = table_resp[e]
        out[e] = Response(r.effect, r.param, r.t, r.S, r.t_bounds, off=r.off, anchor=(ts, S))
    return out


def refine_fit(D, S0, resp: dict, table_resp: dict, fit: Fit, solve, obs, fixed: dict,
               log: dict, before_round: int) -> Fit:
    """Anchor the response of every switched-on effect that needs a contact solve to actual
    solves around its calibrated value (``anchored_responses``; ``resp`` is updated in place)
    and recalibrate, until no estimate leaves its solved interval. Series effects are exact in
    the table (their twist adds to the solved one) and are not anchored. ``log[effect]``
    records where it was solved, or why the table (or the last anchor) was kept."""
    on, done = fit.effects, set()
    for n_solve in range(1, ANCHOR_SOLVES + 2):
        stale = {}
        for k, e in enumerate(on):
            if get_effect(e).series or e in done:
                continue
            a, t = resp[e].anchor, fit.t[k]
            if a is not None:
                pts = anchor_points(table_resp[e], t)
                # inside the solved interval, or pinned where the last anchor was (a bound)
                if a[0][0] <= t <= a[0][-1] or (pts is not None and np.array_equal(pts[0], a[0])):
                    continue
            stale[e] = t
        if not stale:
            return fit
        if n_solve > ANCHOR_SOLVES:
            for e in stale:
                log[e]["status"] = "unsettled"
                log[e]["reason"] = (f"the estimate still left its solved interval after {ANCHOR_SOLVES} "
                                    "solves; the last anchored response is used")
            return fit
        changed = False
        for e, r in anchored_responses(table_resp, stale, solve, obs, fixed).items():
            if isinstance(r, str):
                done.add(e)
                kept = "the last anchored response" if resp[e].anchor is not None else "the table's response"
                log[e] = {**log.get(e, {}), "status": "failed", "reason": f"{r}; {kept} is used"}
                continue
            resp[e], changed = r, True
            log[e] = {"status": "anchored", "before_round": before_round, "param": r.param,
                      "solved_at": [r.value(t) for t in r.anchor[0]], "solves": n_solve}
        if changed:
            fit = calibrate(D, S0, resp, on, start=list(fit.t))
    return fit


def loo_rmse(D, S0, resp, effects, fit: Fit, specimen: np.ndarray) -> float:
    """Leave one specimen out: calibrate on the others, predict the one left out."""
    if not effects:
        return float(np.sqrt(np.mean((S0 - D) ** 2)))
    err = np.zeros(len(D))
    for sid in pd.unique(specimen):
        out = specimen == sid
        f = calibrate(D, S0, resp, effects, start=list(fit.t), mask=~out)
        err[out] = (f.S - D)[out]
    return float(np.sqrt(np.mean(err ** 2)))


def detectability(resp: dict[str, Response], noise: float, n: int, unit: str | None = None,
                  pay_threshold: float = 10.0) -> list[dict]:
    """Could this data show each candidate at its realistic value for ``unit``? (see the
    module docstring)

    ``noise`` is the standard deviation of one observation (arcmin), ``n`` their number.
    Returns one row per candidate: the change at the realistic value (RMS and largest, arcmin),
    the ΔBIC it would earn, the relative standard deviation of its calibrated parameter, the
    noise at which it would just pay and the noise at which its parameter would come out
    within 15 % at two standard deviations."""
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
        rows.append({"effect": name, "param": r.param, "realistic": realistic, "unit": p.unit,
                     "change_rms_arcmin": size / math.sqrt(n), "change_max_arcmin": float(np.max(np.abs(delta))),
                     "expected_delta_bic": float(-n * math.log1p(chi2 / n) + math.log(n)) if math.isfinite(chi2)
                     else -math.inf,
                     "expected_rel_sd": (stretch / math.sqrt(chi2)) if chi2 > 0 else math.inf,
                     "noise_to_show_arcmin": show, "noise_to_calibrate_arcmin": 0.075 * size / stretch,
                     "visible": bool(size > 0 and noise < show)})
    return rows


def plan_detectability(unit: str, specimens: pd.DataFrame, settings: dict, steps_per_ramp: int,
                       noise_arcmin: float, candidates: list[str] | None = None, jobs: int = 1,
                       pay_threshold: float = 10.0) -> dict:
    """Before measuring: which candidates could a test of these specimens show at this noise?

    Solves the campaign tables of ``specimens`` (the baseline model and every candidate's
    grid, as a campaign would) and evaluates ``detectability`` on the curve form of the
    test (every step of every specimen) with ``noise_arcmin`` per point."""
    from hdwf.validation.campaign import candidate_names, plan_variants, specimen_solver

    if not (noise_arcmin > 0 and math.isfinite(noise_arcmin)):
        raise ValueError(f"noise_arcmin must be > 0, got {noise_arcmin!r}")
    candidates = candidate_names({}) if candidates is None else list(candidates)
    plan = plan_variants({}, candidates)
    table = specimen_solver(unit, specimens, settings, steps_per_ramp, jobs)(plan)
    return detectability_of_tables(table, unit, noise_arcmin, candidates, pay_threshold)


def detectability_of_tables(table: pd.DataFrame, unit: str, noise_arcmin: float,
                            candidates: list[str], pay_threshold: float = 10.0) -> dict:
    """``plan_detectability`` on tables already solved (every step of every specimen observed)."""
    base = table[table["variant"] == variant_key({})]
    bad = base[base["status"] != "ok"]
    if len(bad):
        raise RuntimeError(f"the baseline solve failed for specimen {bad['specimen_id'].iloc[0]}: "
                           f"{bad['status'].iloc[0]}")
    obs = base[["specimen_id", "step", "torque_Nm"]].reset_index(drop=True)
    obs["quantity"] = "twist"
    notes: dict[str, str] = {}
    resp = responses(table, obs, {}, candidates, notes)
    return {"unit": unit, "n_specimens": int(base["specimen_id"].nunique()), "n_points": int(len(obs)),
            "noise_arcmin": float(noise_arcmin), "mean_lost_motion_arcmin": mean_lost_motion(table),
            "pay_threshold": pay_threshold, "notes": notes,
            "candidates": detectability(resp, noise_arcmin, len(obs), unit, pay_threshold)}


def _cosine(a: np.ndarray, b: np.ndarray) -> float:
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    return float(a @ b / (na * nb)) if na > 0 and nb > 0 else 0.0


# ------------------------------------------------------------------ the diagnosis

def diagnose(meas, table: pd.DataFrame, fixed: dict | None = None, calibrate_first: list[str] | None = None,
             candidates: list[str] | None = None, max_rounds: int = 2, pay_threshold: float = 10.0,
             tie_threshold: float = 6.0, solve=None) -> tuple[dict, pd.DataFrame]:
    """The campaign's diagnosis (the content of ``diagnosis.json``) and its comparison points
    (one row per observation: measured ``D``, the campaign model ``S_model`` and the model
    with every found effect at its calibrated value ``S_final``).

    With ``solve`` (variants -> table rows of every specimen, ``hdwf.validation.campaign.specimen_solver``)
    every effect switched on before a round (calibrated first, or found in the previous round)
    that needs a contact solve (not the series ones, exact in the tables) is recalibrated on
    actual solves around its estimate (``refine_fit``), so that the round's candidates are
    weighed against the FE model, not against the tables' interpolation error; after the last
    round the ladder's actual solves check the result. Without ``solve``, the tables' splines
    serve throughout. ``refinement`` in the result says what was solved where."""
    from hdwf.validation.campaign import candidate_names

    fixed = dict(fixed or {})
    calibrate_first = list(calibrate_first or [])
    if candidates is None:
        candidates = candidate_names(fixed)
    obs = observation_frame(meas)
    D = obs["D"].to_numpy(float)
    spec = obs["specimen_id"].to_numpy()
    S0 = predict(table, obs, variant_key(fixed))
    failed = ~np.isfinite(S0)
    if failed.any():
        bad = sorted(set(spec[failed]))
        raise RuntimeError(f"the campaign model failed to solve for specimen(s) {', '.join(bad)}; "
                           "see their tables' status")
    notes: dict[str, str] = {}
    refinement: dict[str, dict] = {}
    resp = responses(table, obs, fixed, candidates, notes)
    table_resp = dict(resp)        # the tables' splines; ``resp`` may get refined ones
    candidates = [c for c in candidates if c in resp]

    def refined(fit: Fit, before_round: int) -> Fit:
        if solve is None:
            return fit
        return refine_fit(D, S0, resp, table_resp, fit, solve, obs, fixed, refinement, before_round)

    on: list[str] = []
    fit = Fit([], np.zeros(0), np.zeros((0, 0)), S0, float(np.sum((S0 - D) ** 2)), len(D))
    for e in calibrate_first:                        # effects the campaign says to calibrate
        on.append(e)
        fit = calibrate(D, S0, resp, on, start=list(fit.t))
    if on:
        fit = refined(fit, 1)
    rounds = []
    remaining = [c for c in candidates if c not in on]
    for rnd in range(1, max_rounds + 1):
        cur = Candidate("current model", {}, fit.rss, len(D), len(on), loo_rmse(D, S0, resp, on, fit, spec))
        resid = D - fit.S
        cands, extra = [], {}
        for e in remaining:
            f = calibrate(D, S0, resp, on + [e], start=list(fit.t))
            cands.append(Candidate(e, f.params(resp)[e], f.rss, len(D), len(on) + 1,
                                   loo_rmse(D, S0, resp, on + [e], f, spec)))
            t_e = f.t[-1]
            lo, hi = resp[e].t_bounds
            tol = 1e-6 * max(abs(lo), abs(hi))
            extra[e] = {"param_sd": f.param_sd(resp)[e],
                        "signature_match": _cosine(resid, f.S - fit.S),
                        "at_bound": bool(abs(t_e) > tol and (abs(t_e - lo) <= tol or abs(t_e - hi) <= tol)),
                        "off": bool(abs(t_e) <= tol),
                        "fit": f}
        v = verdict(cur, cands, pay_threshold, tie_threshold)
        for r in v["ranking"]:
            x = extra[r["effect"]]
            r.update({"param_sd": None if x["off"] else x["param_sd"],
                      "signature_match": x["signature_match"], "at_bound": x["at_bound"],
                      "calibrated_off": x["off"], "signature": get_effect(r["effect"]).signature,
                      # the effects already on, recalibrated jointly with this candidate
                      "with_effects": {k: v for k, v in x["fit"].params(resp).items() if k != r["effect"]}})
        rounds.append({"round": rnd, "model_effects": list(on), "current_rmse_arcmin": cur.rmse,
                       "ranking": v["ranking"], "verdict": v["verdict"]})
        winner = v["verdict"]["missing_effect"]
        if winner is None:
            break
        on.append(winner)
        remaining.remove(winner)
        fit = extra[winner]["fit"]
        if not remaining or rnd == max_rounds:
            break
        fit = refined(fit, rnd + 1)      # the next round's candidates are calibrated on top of it

    base_points = comparison_points(_measured_for_points(obs), _predicted_for_points(obs, S0), "value")
    for c in meas.specimens.columns:
        if c.endswith("_mm") and c not in base_points:
            base_points = base_points.merge(meas.specimens[["specimen_id", c]], on="specimen_id")
    summary, per = summarise(base_points)
    tests = residual_tests(base_points)
    first = rounds[0]
    found = [{"effect": e, "params": fit.params(resp)[e], "param_sd": fit.param_sd(resp)[e]} for e in on]
    final_rmse = float(np.sqrt(fit.rss / len(D)))
    noise = float(np.sqrt(np.nanmean(obs["u_D"].to_numpy(float) ** 2))) if np.isfinite(obs["u_D"]).any() else None
    if noise is not None:
        sigma, sigma_from = noise, "the noise stated in the measurement file"
    else:
        sigma = float(np.sqrt(fit.rss / max(len(D) - len(on), 1)))
        sigma_from = "the residual of the final model (no noise stated: an upper bound on the noise)"
    units = meas.units
    seen = detectability(table_resp, sigma, len(D), units[0] if len(units) == 1 else None, pay_threshold)
    points = obs.copy()
    points["S_model"] = S0
    points["S_final"] = fit.S
    points = points.merge(meas.specimens[["specimen_id", *[c for c in meas.specimens.columns
                                                            if c.endswith("_mm")]]], on="specimen_id")
    if "branch" in base_points:
        points["branch"] = base_points["branch"].to_numpy()
    result = {
        "form": meas.form, "n_points": int(len(D)), "n_specimens": int(len(pd.unique(spec))),
        "noise_arcmin": noise,
        "model": {"fixed": fixed, "calibrated_first": calibrate_first},
        "baseline": {"rmse_arcmin": summary.rmse, "bias_arcmin": summary.bias,
                     "max_abs_arcmin": summary.max_abs, "worst_specimen": summary.worst_specimen,
                     "u_val_arcmin": None if math.isnan(summary.u_val) else summary.u_val,
                     "share_beyond_2uval": None if math.isnan(summary.share_beyond_2uval)
                     else summary.share_beyond_2uval},
        "ranking": first["ranking"],
        "verdict": {**first["verdict"],
                    "found_in_order": [f["effect"] for f in found if f["effect"] not in calibrate_first],
                    # not found, and not visible at a realistic value: the verdict is silent on them
                    "could_not_see": [r["effect"] for r in seen if not r["visible"] and r["effect"] not in on]},
        "detectability": {"noise_arcmin": sigma, "noise_from": sigma_from, "pay_threshold": pay_threshold,
                          "candidates": seen},
        "rounds": rounds,
        "found": found,
        "final": {"effects": fit.params(resp), "rmse_arcmin": final_rmse,
                  "rmse_over_noise": (final_rmse / noise) if noise else None},
        "notes": notes,
        "refinement": refinement,
        "worst_specimens": per.head(5).to_dict(orient="records"),
        "per_specimen": per.to_dict(orient="records"),
        "residual_tests": tests.to_dict(orient="records"),
    }
    return result, points


def _measured_for_points(obs: pd.DataFrame) -> pd.DataFrame:
    m = obs.rename(columns={"D": "value"}).copy()
    m["step"] = m["step"] if "step" in m else np.arange(len(m))
    if "u_D" in m:
        m["u_arcmin"] = m["u_D"]
    return m.drop(columns=["u_D"])


def _predicted_for_points(obs: pd.DataFrame, S: np.ndarray) -> pd.DataFrame:
    p = obs[["specimen_id"]].copy()
    p["step"] = obs["step"] if "step" in obs else np.arange(len(obs))
    p["value"] = S
    return p


def ladder_variants(diagnosis: dict) -> list[tuple[str, dict]]:
    """The model variants of the ladder, in order: the bare baseline, the campaign's model,
    then each found effect switched on at its calibrated value (cumulative)."""
    fixed = diagnosis["model"]["fixed"]
    rungs = [("baseline", {})]
    if fixed:
        rungs.append(("campaign model", dict(fixed)))
    cur = dict(fixed)
    for f in diagnosis["found"]:
        cur = {**cur, f["effect"]: f["params"]}
        rungs.append(("with " + ", ".join(e for e in cur if e not in fixed), dict(cur)))
    return rungs


def ladder_table(meas, table: pd.DataFrame, diagnosis: dict) -> pd.DataFrame:
    """One row per model variant of the ladder, from actual solves (``table``)."""
    import json

    obs = observation_frame(meas)
    D = obs["D"].to_numpy(float)
    rows, b0 = [], None
    for k, (label, eff) in enumerate(ladder_variants(diagnosis)):
        S = predict(table, obs, variant_key(eff))
        n_par = sum(len(v) for v in eff.values())
        rss = float(np.nansum((S - D) ** 2))
        b = bic(rss, len(D), n_par)
        b0 = b if b0 is None else b0
        rows.append({"rung": k, "model": label, "effects": json.dumps(eff, sort_keys=True),
                     "n_params": n_par, "rmse_arcmin": float(np.sqrt(rss / len(D))),
                     "bias_arcmin": float(np.nanmean(S - D)), "max_abs_arcmin": float(np.nanmax(np.abs(S - D))),
                     "delta_bic": float(b - b0), "solved": bool(np.isfinite(S).all())})
    return pd.DataFrame(rows)


__all__ = ["diagnose", "ladder_table", "ladder_variants", "calibrate", "observation_frame", "predict",
           "responses"]


def json_safe(obj):
    """JSON without NaN/inf (null instead), numpy scalars as Python numbers."""
    if isinstance(obj, dict):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


# ------------------------------------------------------------------ workflow stages

def diagnosis_stage(measurements_path, table_paths, plan, out_json, out_points, provenance: dict,
                    jobs: int = 1) -> dict:
    """Diagnose one campaign from its measurement file and per-specimen tables; the solves
    that anchor an effect found before the next round run here, in ``jobs`` processes."""
    from hdwf.validation.campaign import specimen_solver
    from hdwf.common.io import write_json, write_parquet
    from hdwf.validation.measurements import load_measurements

    meas = load_measurements(measurements_path)
    table = pd.concat([pd.read_parquet(p) for p in table_paths], ignore_index=True)

    solve = specimen_solver(plan.unit, meas.specimens, plan.settings, plan.steps_per_ramp, jobs)
    result, points = diagnose(meas, table, plan.fixed, plan.calibrate_first, plan.candidates, plan.rounds,
                              solve=solve)
    result = {"campaign": plan.name, "unit": plan.unit, "measurements": str(measurements_path),
              "mesh": plan.settings, **result, "provenance": provenance}
    write_parquet(points, out_points, provenance=provenance, meta={"campaign": plan.name, "unit": plan.unit})
    write_json(json_safe(result), out_json)
    return result


def ladder_stage(measurements_path, diagnosis_json, table_paths, out, provenance: dict,
                 unit: str, settings: dict, steps_per_ramp: int, jobs: int = 1) -> pd.DataFrame:
    """The ladder of a campaign from actual solves: every rung's variant is looked up in the
    specimens' tables and solved (mesh, wave generator and the missing variants only) where a
    table lacks it, i.e. for the found effects at their calibrated values."""
    import json

    from hdwf.validation.campaign import solve_specimens
    from hdwf.common.io import write_parquet
    from hdwf.validation.measurements import load_measurements

    meas = load_measurements(measurements_path)
    diag = json.loads(open(diagnosis_json).read())
    table = pd.concat([pd.read_parquet(p) for p in table_paths], ignore_index=True)
    rungs = [eff for _, eff in ladder_variants(diag)]
    have = table.groupby("specimen_id")["variant"].agg(set).to_dict()
    todo = {sid: [eff for eff in rungs if variant_key(eff) not in have.get(sid, set())]
            for sid in meas.specimens["specimen_id"]}
    need = meas.specimens[[bool(todo[sid]) for sid in meas.specimens["specimen_id"]]]
    if len(need):
        solved = solve_specimens(unit, need, settings, steps_per_ramp, todo.__getitem__, jobs=jobs)
        table = pd.concat([table, solved], ignore_index=True)
    ladder = ladder_table(meas, table, diag)
    write_parquet(ladder, out, provenance=provenance,
                  meta={"campaign": diag["campaign"], "unit": diag["unit"],
                        "solved_for_ladder": int(sum(len(v) for v in todo.values()))})
    return ladder
