"""Which physical effect is the model missing? The greedy search and its result.

Inputs: checked measurements (``hdwf.validation.measurements``) and the per-specimen tables of
the FE model (``hdwf.validation.variants``): the campaign's model and, for every candidate
effect, the model with that effect at each value of its parameter's grid.

Method (see docs/validation.md; calibration in ``hdwf.validation.calibration``):

* effects the campaign says to calibrate are switched on and calibrated first;
* each round, every remaining candidate is added to the effects already on and all switched-on
  parameters are calibrated together;
* evidence: ΔBIC against the model without the candidate, the leave-one-specimen-out error,
  and how well the change the effect makes lines up with the residual it should explain
  (cosine: 1 = the same pattern);
* verdict (``hdwf.validation.comparison.verdict``): a candidate pays when ΔBIC <= -10 and its
  leave-one-out error beats the current model's; paying candidates within ΔBIC 6 of the
  best are reported as indistinguishable; none paying -> "no missing effect found";
* greedy: the winner is switched on and the search repeats for the next effect; with a
  ``solve``, an effect switched on before a round is first recalibrated on actual solves
  around its estimate (``calibration.refine_fit``);
* what the data could see (``hdwf.validation.detectability``) against the noise it states,
  or else the final model's residual (an upper bound).

``diagnose`` returns a ``Diagnosis``; ``Diagnosis.to_dict`` is the content of ``diagnosis.json``.
"""

from __future__ import annotations

import logging
import math
from dataclasses import asdict, dataclass, field
from typing import Callable

import numpy as np
import pandas as pd

from hdwf.validation.calibration import (CalibrationData, Fit, Refinement, Resolver, Response, calibrate,
                                         loo_rmse, refine_fit, responses)
from hdwf.validation.comparison import Candidate, Summary, Verdict, residual_tests, summarise, verdict
from hdwf.validation.detectability import Visibility, detectability
from hdwf.validation.effects import get as get_effect
from hdwf.validation.measurements import Measurements
from hdwf.validation.observations import observation_frame, predict, prediction_points
from hdwf.validation.noise import NoiseCheck
from hdwf.validation.signature import ResidualSignature, residual_signature, with_verdict
from hdwf.validation.variants import candidate_names, variant_key

log = logging.getLogger(__name__)


# a candidate takes out a component of the residual when it leaves at most this share of it
TAKE_OUT_SHARE = 0.5


@dataclass(frozen=True)
class Search:
    """What a diagnosis searches and how it decides.

    Attributes
    ----------
    fixed : dict
        Effects switched on in the campaign's model, ``{effect: {param: value}}``.
    calibrate_first : list of str
        Effects switched on and calibrated before the search.
    candidates : list of str, optional
        The effects to try (default: every registered effect not in ``fixed``).
    max_rounds : int
        At most this many effects are found.
    pay_threshold, tie_threshold : float
        The ΔBIC a candidate must earn, and the gap below which two paying ones are a tie.
    """

    fixed: dict = field(default_factory=dict)
    calibrate_first: list[str] = field(default_factory=list)
    candidates: list[str] | None = None
    max_rounds: int = 2
    pay_threshold: float = 10.0
    tie_threshold: float = 6.0


@dataclass(frozen=True)
class Evidence:
    """What a round adds to a candidate's ranking row, besides its fit and ΔBIC."""

    param_sd: float | None       # None when it calibrated to "off"
    signature_match: float       # cosine of its change with the current model's residual
    at_bound: bool               # its estimate sits at a bound of its range
    calibrated_off: bool
    signature: str               # the effect's documented signature
    with_effects: dict           # the effects already on, recalibrated jointly with it


@dataclass(frozen=True)
class Round:
    """One round of the search: the model it started from and the ranked candidates."""

    number: int
    model_effects: list[str]
    current_rmse_arcmin: float
    verdict: Verdict
    evidence: dict[str, Evidence]

    def ranking(self) -> list[dict]:
        """The ranking rows: each candidate's fit, ΔBIC and evidence."""
        return [{**asdict(r), **asdict(self.evidence[r.effect])} for r in self.verdict.ranking]

    def to_dict(self) -> dict:
        """The round as ``diagnosis.json`` gives it."""
        return {"round": self.number, "model_effects": list(self.model_effects),
                "current_rmse_arcmin": self.current_rmse_arcmin, "ranking": self.ranking(),
                "verdict": self.verdict.decision()}


@dataclass(frozen=True)
class Found:
    """An effect switched on in the final model (calibrated first, or found), calibrated."""

    effect: str
    params: dict
    param_sd: float


@dataclass(frozen=True)
class DataDetectability:
    """What this data could show (``hdwf.validation.detectability``) at the noise it was judged by."""

    noise_arcmin: float
    noise_from: str
    pay_threshold: float
    candidates: list[Visibility]


@dataclass
class Diagnosis:
    """A campaign's diagnosis and its comparison points."""

    form: str                      # of the measurement file
    n_points: int
    n_specimens: int
    noise_arcmin: float | None     # the noise the measurement file states (RMS), None when none
    fixed: dict
    calibrated_first: list[str]
    baseline: Summary              # the campaign model against the data
    rounds: list[Round]
    found: list[Found]
    final_effects: dict            # every effect of the final model at its calibrated value
    final_rmse_arcmin: float
    detectability: DataDetectability
    notes: dict[str, str]          # {effect: why (part of) its grid was not used}
    refinement: dict[str, Refinement]          # before a further round
    final_refinement: dict[str, Refinement]    # after the last round, for the final model
    per_specimen: pd.DataFrame     # the campaign model's error per specimen, worst first
    residual_tests: pd.DataFrame
    # one row per observation: measured D, the campaign model S_model and the final model S_final
    points: pd.DataFrame
    signature: ResidualSignature   # what the campaign model's residual D - S looks like

    @property
    def found_in_order(self) -> list[str]:
        """The effects the search found, in order (not those calibrated first)."""
        return [f.effect for f in self.found if f.effect not in self.calibrated_first]

    @property
    def could_not_see(self) -> list[str]:
        """Candidates not found and not visible at a realistic value: the verdict is silent on them."""
        on = {f.effect for f in self.found}
        return [r.effect for r in self.detectability.candidates if not r.visible and r.effect not in on]

    def to_dict(self) -> dict:
        """The content of ``diagnosis.json`` (without the campaign's name, files and provenance)."""
        first = self.rounds[0]
        b = self.baseline
        return {
            "form": self.form, "n_points": self.n_points, "n_specimens": self.n_specimens,
            "noise_arcmin": self.noise_arcmin,
            "model": {"fixed": self.fixed, "calibrated_first": self.calibrated_first},
            "baseline": {"rmse_arcmin": b.rmse, "bias_arcmin": b.bias, "max_abs_arcmin": b.max_abs,
                         "worst_specimen": b.worst_specimen,
                         "u_val_arcmin": None if math.isnan(b.u_val) else b.u_val,
                         "share_beyond_2uval": None if math.isnan(b.share_beyond_2uval) else b.share_beyond_2uval},
            "ranking": first.ranking(),
            "verdict": {**first.verdict.decision(), "found_in_order": self.found_in_order,
                        "could_not_see": self.could_not_see},
            "detectability": asdict(self.detectability),
            "rounds": [r.to_dict() for r in self.rounds],
            "found": [asdict(f) for f in self.found],
            "final": {"effects": self.final_effects, "rmse_arcmin": self.final_rmse_arcmin,
                      "rmse_over_noise": (self.final_rmse_arcmin / self.noise_arcmin) if self.noise_arcmin else None,
                      "refinement": {e: r.as_dict() for e, r in self.final_refinement.items()}},
            "notes": self.notes,
            "refinement": {e: r.as_dict() for e, r in self.refinement.items()},
            "worst_specimens": self.per_specimen.head(5).to_dict(orient="records"),
            "per_specimen": self.per_specimen.to_dict(orient="records"),
            "residual_tests": self.residual_tests.to_dict(orient="records"),
            "signature": self.signature.to_dict(),
        }


def _cosine(a: np.ndarray, b: np.ndarray) -> float:
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    return float(a @ b / (na * nb)) if na > 0 and nb > 0 else 0.0


def _evidence(resp: dict[str, Response], effect: str, f: Fit, current: Fit, resid: np.ndarray) -> Evidence:
    """A candidate's evidence from its joint fit ``f`` on top of the ``current`` model's fit,
    whose residual (measured minus predicted) is ``resid``."""
    t_e = f.t[-1]
    lo, hi = resp[effect].t_bounds
    tol = 1e-6 * max(abs(lo), abs(hi))
    off = bool(abs(t_e) <= tol)
    return Evidence(param_sd=None if off else f.param_sd(resp)[effect],
                    signature_match=_cosine(resid, f.S - current.S),
                    at_bound=bool(abs(t_e) > tol and (abs(t_e - lo) <= tol or abs(t_e - hi) <= tol)),
                    calibrated_off=off, signature=get_effect(effect).signature,
                    with_effects={k: v for k, v in f.params(resp).items() if k != effect})


class _GreedySearch:
    """The state of one search: the effects switched on, their joint fit, the rounds so far."""

    def __init__(self, data: CalibrationData, specimen: np.ndarray, search: Search, resolver: Resolver | None,
                 takes_out: Callable[[np.ndarray, np.ndarray], bool] | None = None):
        self.data, self.specimen, self.search, self.resolver = data, specimen, search, resolver
        self.takes_out = takes_out   # (S before, S with a candidate) -> it takes out the clearest component
        self.refinement: dict[str, Refinement] = {}         # before a further round
        self.final_refinement: dict[str, Refinement] = {}   # for the final model
        self.on: list[str] = []
        self.rounds: list[Round] = []
        D, S0 = data.D, data.S0
        self.fit = Fit([], np.zeros(0), np.zeros((0, 0)), S0, float(np.sum((S0 - D) ** 2)), len(D))

    def refine(self, before_round: int | None) -> None:
        """With a solver, recalibrate the switched-on effects on actual solves near their
        estimates: before round ``before_round``, or for the final model (None)."""
        if self.resolver is not None:
            where = self.refinement if before_round is not None else self.final_refinement
            self.fit = refine_fit(self.data, self.fit, self.resolver, where, before_round)
            when = f"before round {before_round}" if before_round is not None else "for the final model"
            for effect, entry in where.items():
                if entry.before_round == before_round:
                    at = ", ".join(f"{v:.5g}" for v in entry.solved_at or [])
                    log.info("%s, %s: %s%s; now %s", when, effect, entry.status,
                             f" ({entry.param} solved at {at})" if at else f" ({entry.reason})",
                             self.fit.params(self.data.resp).get(effect))

    def calibrate_first(self, effects: list[str]) -> None:
        """Switch ``effects`` on and calibrate them before the search (recalibrated on solves)."""
        for e in effects:
            self.on.append(e)
            self.fit = calibrate(self.data, self.on, start=list(self.fit.t))
        if self.on:
            self.refine(1)

    def round(self, number: int, remaining: list[str]) -> dict[str, Fit]:
        """Calibrate every remaining candidate on top of the current model and rank them;
        returns each candidate's joint fit."""
        data, fit, on, n = self.data, self.fit, self.on, len(self.data.D)
        cur = Candidate("current model", {}, fit.rss, n, len(on), loo_rmse(data, on, fit, self.specimen))
        resid = data.D - fit.S
        cands, evidence, fits = [], {}, {}
        for e in remaining:
            f = calibrate(data, on + [e], start=list(fit.t))
            cands.append(Candidate(e, f.params(data.resp)[e], f.rss, n, len(on) + 1,
                                   loo_rmse(data, on + [e], f, self.specimen)))
            evidence[e] = _evidence(data.resp, e, f, fit, resid)
            fits[e] = f
        takes_out = {e: self.takes_out(fit.S, f.S) for e, f in fits.items()} if self.takes_out else None
        v = verdict(cur, cands, self.search.pay_threshold, self.search.tie_threshold, takes_out)
        self.rounds.append(Round(number, list(on), cur.rmse, v, evidence))
        log.info("round %d on %s (RMSE %.4f arcmin): %s; ranked %s", number, list(on) or "the campaign's model",
                 cur.rmse, v.text, ", ".join(f"{r.effect} ΔBIC {r.delta_bic:.1f} RMSE {r.rmse_arcmin:.4f}"
                                             for r in v.ranking))
        return fits

    def run(self, candidates: list[str]) -> None:
        """Rounds until no candidate pays, none is left or ``max_rounds`` effects are found."""
        remaining = [c for c in candidates if c not in self.on]
        for number in range(1, self.search.max_rounds + 1):
            fits = self.round(number, remaining)
            winner = self.rounds[-1].verdict.missing_effect
            if winner is None:
                break
            self.on.append(winner)
            remaining.remove(winner)
            self.fit = fits[winner]
            if not remaining or number == self.search.max_rounds:
                break
            self.refine(number + 1)      # the next round's candidates are calibrated on top of it
        # the last round's estimates come from the tables (or from solves they have left): the
        # final model, which the ladder re-solves, is calibrated on actual solves too
        self.refine(None)


def _calibration_data(table: pd.DataFrame, obs: pd.DataFrame, search: Search
                      ) -> tuple[CalibrationData, list[str], dict[str, str]]:
    """The measured values, the campaign model's prediction and the candidates' responses;
    the candidates that can be calibrated, and notes on those that cannot (fully)."""
    fixed = dict(search.fixed)
    candidates = candidate_names(fixed) if search.candidates is None else list(search.candidates)
    D = obs["D"].to_numpy(float)
    S0 = predict(table, obs, variant_key(fixed))
    failed = ~np.isfinite(S0)
    if failed.any():
        bad = sorted(set(obs["specimen_id"].to_numpy()[failed]))
        raise RuntimeError(f"the campaign model failed to solve for specimen(s) {', '.join(bad)}; "
                           "see their tables' status")
    notes: dict[str, str] = {}
    resp = responses(table, obs, fixed, candidates, notes)
    return CalibrationData(D, S0, resp), [c for c in candidates if c in resp], notes


def _points(meas: Measurements, obs: pd.DataFrame, S_model: np.ndarray, S_final: np.ndarray,
            base_points: pd.DataFrame) -> pd.DataFrame:
    """One row per observation with the campaign model's and the final model's prediction."""
    points = obs.copy()
    points["S_model"] = S_model
    points["S_final"] = S_final
    points = points.merge(meas.specimens[["specimen_id", *[c for c in meas.specimens.columns
                                                            if c.endswith("_mm")]]], on="specimen_id")
    if "branch" in base_points:
        points["branch"] = base_points["branch"].to_numpy()
    return points


def _noise(obs: pd.DataFrame, g: _GreedySearch, check: NoiseCheck) -> tuple[float | None, float, str]:
    """The noise the file states (RMS, None when none), and the noise the detectability is judged by:
    the stated one, unless the signature's check found it far below the data's scatter (then that
    estimate), or the final model's residual when none is stated."""
    u = obs["u_D"].to_numpy(float)
    noise = float(np.sqrt(np.nanmean(u ** 2))) if np.isfinite(obs["u_D"]).any() else None
    if noise is not None and check.flag and check.estimate_arcmin:
        return noise, check.estimate_arcmin, (f"the scatter estimated from the data ({check.estimate_from}): the "
                                              f"stated uncertainty, {noise:.3g} arcmin RMS, is far below it")
    if noise is not None:
        return noise, noise, "the noise stated in the measurement file"
    dof = max(len(g.data.D) - len(g.on), 1)
    sigma = float(np.sqrt(g.fit.rss / dof))
    return None, sigma, (f"no noise is stated: the residual of the search's final fit on the tabulated solves, "
                         f"sqrt(RSS / {dof}) over {len(g.data.D)} values less {len(g.on)} calibrated parameters, an "
                         "upper bound on the noise; the ladder's re-solved RMSE can differ")


def _signature(form: str, base_points: pd.DataFrame, g: _GreedySearch, final_rmse_arcmin: float) -> ResidualSignature:
    """The signature of the campaign model's residual, its text naming what the search found (or
    the closest candidate of round 1 when it found nothing)."""
    found = [e for e in g.on if e not in g.search.calibrate_first]
    first = g.rounds[0]
    closest = first.verdict.ranking[0] if first.verdict.ranking and not found else None
    at_bound = closest is not None and first.evidence[closest.effect].at_bound
    return with_verdict(residual_signature(base_points, form), found, final_rmse_arcmin, closest, at_bound,
                        first.current_rmse_arcmin)


def _residual_points(meas: Measurements, obs: pd.DataFrame, S: np.ndarray) -> pd.DataFrame:
    """The observations against a prediction, with each specimen's parameters (for the trends)."""
    points = prediction_points(obs, S)
    for c in meas.specimens.columns:
        if c.endswith("_mm") and c not in points:
            points = points.merge(meas.specimens[["specimen_id", c]], on="specimen_id")
    return points


def _component_judge(meas: Measurements, obs: pd.DataFrame) -> Callable[[np.ndarray, np.ndarray], bool]:
    """``judge(S_before, S_after)``: does the change take out the clearest component of the
    residual D − S_before (``ResidualSignature.clearest_component``)? Each of its terms must fall
    to ``TAKE_OUT_SHARE`` of its size or below significance. True when nothing stands out."""
    before: dict[bytes, ResidualSignature] = {}

    def judge(S_before: np.ndarray, S_after: np.ndarray) -> bool:
        key = np.asarray(S_before, float).tobytes()
        if key not in before:
            before[key] = residual_signature(_residual_points(meas, obs, S_before), meas.form)
        sig = before[key]
        if not sig.clearest_component:
            return True
        after = residual_signature(_residual_points(meas, obs, S_after), meas.form)
        return all(not after.term(n).significant or abs(after.term(n).value) <= TAKE_OUT_SHARE * abs(sig.term(n).value)
                   for n in sig.clearest_component)
    return judge


def _diagnosis(meas: Measurements, obs: pd.DataFrame, g: _GreedySearch, table_resp: dict[str, Response],
               notes: dict[str, str]) -> Diagnosis:
    """The result of a finished search."""
    base_points = _residual_points(meas, obs, g.data.S0)
    summary, per = summarise(base_points)
    tests = residual_tests(base_points)
    resp, fit, n = g.data.resp, g.fit, len(g.data.D)
    found = [Found(e, fit.params(resp)[e], fit.param_sd(resp)[e]) for e in g.on]
    final_rmse = float(np.sqrt(fit.rss / n))
    signature = _signature(meas.form, base_points, g, final_rmse)
    noise, sigma, sigma_from = _noise(obs, g, signature.noise)
    units = meas.units
    pay = g.search.pay_threshold
    seen = detectability(table_resp, sigma, n, units[0] if len(units) == 1 else None, pay)
    return Diagnosis(
        form=meas.form, n_points=int(n), n_specimens=int(len(pd.unique(g.specimen))), noise_arcmin=noise,
        fixed=dict(g.search.fixed), calibrated_first=list(g.search.calibrate_first), baseline=summary,
        rounds=g.rounds, found=found, final_effects=fit.params(resp),
        final_rmse_arcmin=final_rmse,
        detectability=DataDetectability(sigma, sigma_from, pay, seen), notes=notes, refinement=g.refinement,
        final_refinement=g.final_refinement,
        per_specimen=per, residual_tests=tests, points=_points(meas, obs, g.data.S0, fit.S, base_points),
        signature=signature)


def diagnose(meas: Measurements, table: pd.DataFrame, search: Search | None = None,
             solve: Callable[[list[dict]], pd.DataFrame] | None = None) -> Diagnosis:
    """The campaign's diagnosis: calibrate every candidate, rank, decide; repeat for the next effect.

    Parameters
    ----------
    meas : Measurements
        The checked measurements.
    table : pandas.DataFrame
        The campaign's tables (``hdwf.validation.variants``): the campaign model and every
        candidate's grid, for every specimen.
    search : Search, optional
        The campaign's model, candidates and thresholds (default: ``Search()``).
    solve : callable, optional
        ``solve(variants)``: the table rows of every specimen for those variants
        (``hdwf.validation.variants.specimen_solver``). With it, every effect switched on before
        a round (calibrated first, or found in the previous round) that needs a contact solve
        (not the series ones, exact in the tables) is recalibrated on actual solves around its
        estimate (``calibration.refine_fit``), so that the round's candidates are weighed
        against the FE model, not against the tables' interpolation error. Without it, the
        tables' splines serve throughout. After the last round the final model is treated the
        same way (an estimate outside its solves is solved around once more), so the values
        the ladder re-solves rest on the FE model too.

    Returns
    -------
    Diagnosis
        The rounds, the found effects, the final model, what the data could show, where the
        model was re-solved (``refinement`` before a round, ``final_refinement`` for the final
        model) and the comparison points.
    """
    search = Search() if search is None else search
    obs = observation_frame(meas)
    data, candidates, notes = _calibration_data(table, obs, search)
    table_resp = dict(data.resp)        # the tables' splines; ``data.resp`` may get anchored ones
    resolver = None if solve is None else Resolver(solve, obs, dict(search.fixed), table_resp)
    g = _GreedySearch(data, obs["specimen_id"].to_numpy(), search, resolver, _component_judge(meas, obs))
    g.calibrate_first(list(search.calibrate_first))
    g.run(candidates)
    return _diagnosis(meas, obs, g, table_resp, notes)
