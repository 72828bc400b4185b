"""The error ladder: the model's error, rung by rung, as found effects are switched on.

Its rungs are the bare baseline, the campaign's model, then each found effect switched on at
its calibrated value (cumulative); every rung is judged on actual solves, which checks the
superposition the diagnosis calibrated with.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

from hdwf.fe.hertz import ISO76_BALL_PRESSURE_MPA
from hdwf.validation.comparison import bic
from hdwf.validation.measurements import Measurements
from hdwf.validation.observations import observation_frame, predict
from hdwf.validation.variants import SolveSetup, solve_specimens, variant_key


def ladder_variants(fixed: dict, found: list[tuple[str, dict]]) -> list[tuple[str, dict]]:
    """The model variants of the ladder, in order.

    Parameters
    ----------
    fixed : dict
        The campaign model's effects, ``{effect: {param: value}}``.
    found : list of tuple
        ``(effect, params)`` of each effect of the final model, in the order it was switched on.

    Returns
    -------
    list of tuple
        ``(label, effects)``: the bare baseline, the campaign's model (when it has effects),
        then each found effect switched on at its calibrated value (cumulative).
    """
    rungs = [("baseline", {})]
    if fixed:
        rungs.append(("campaign model", dict(fixed)))
    cur = dict(fixed)
    for effect, params in found:
        cur = {**cur, effect: params}
        rungs.append(("with " + ", ".join(e for e in cur if e not in fixed), dict(cur)))
    return rungs


def ladder_table(meas: Measurements, table: pd.DataFrame, rungs: list[tuple[str, dict]]) -> pd.DataFrame:
    """One row per rung of the ladder, from actual solves.

    Parameters
    ----------
    meas : Measurements
        The checked measurements.
    table : pandas.DataFrame
        Tables holding every rung's variant for every specimen.
    rungs : list of tuple
        ``(label, effects)`` (``ladder_variants``).

    Returns
    -------
    pandas.DataFrame
        ``rung``, ``model``, ``effects`` (JSON), ``n_params``, ``rmse_arcmin``, ``bias_arcmin``,
        ``max_abs_arcmin``, ``delta_bic`` (against the first rung that solved every specimen,
        ``delta_bic_against_rung``; -1 when none did), ``solved``,
        ``failed_specimens`` (comma-separated; empty when every solve succeeded), and the bearing
        check of the rung's model (``bearing_check``): the largest ball pressure at the mount over
        the specimens and how many exceed ISO 76's static rating; the solver's own check
        (``contact_check``). A rung whose solve failed for
        any specimen has no error figures (NaN): scored on the specimens left, it would look
        better than a rung that solved them all.
    """
    obs = observation_frame(meas)
    D = obs["D"].to_numpy(float)
    rows = []
    for k, (label, eff) in enumerate(rungs):
        S = predict(table, obs, variant_key(eff))
        n_par = sum(len(v) for v in eff.values())
        solved = np.isfinite(S)
        E = np.where(solved.all(), S - D, np.nan)
        rows.append({"rung": k, "model": label, "effects": json.dumps(eff, sort_keys=True),
                     "n_params": n_par, "rmse_arcmin": float(np.sqrt(np.mean(E ** 2))),
                     "bias_arcmin": float(np.mean(E)), "max_abs_arcmin": float(np.max(np.abs(E))),
                     "bic": bic(float(np.sum(E ** 2)), len(D), n_par), "solved": bool(solved.all()),
                     "failed_specimens": ", ".join(sorted(set(obs["specimen_id"].to_numpy()[~solved]))),
                     **bearing_check(table, variant_key(eff)), **contact_check(table, variant_key(eff))})
    ladder = pd.DataFrame(rows)
    # against the first rung that has a BIC: a failed baseline leaves the later rungs comparable
    finite = ladder["bic"].notna()
    ladder.insert(ladder.columns.get_loc("bic"), "delta_bic",
                  ladder["bic"] - (ladder.loc[finite, "bic"].iloc[0] if finite.any() else np.nan))
    ladder["delta_bic_against_rung"] = int(ladder.loc[finite, "rung"].iloc[0]) if finite.any() else -1
    return ladder.drop(columns="bic")


def bearing_check(table: pd.DataFrame, key: str) -> dict:
    """The wave-generator bearing under variant ``key``: is a found effect physically admissible?

    An effect calibrated to the data may ask for more than the drive can take: a tooth
    interference that presses the wave generator's balls into their raceways beyond the
    static rating (ISO 76: 4200 MPa at the most loaded contact), where a real bearing would
    dent at assembly. Returns ``ball_pressure_max_MPa`` (the largest over the specimens),
    ``specimens_above_iso76`` and ``specimens_checked`` (specimens with a solved pressure);
    NaN / 0 for tables made before the column existed.
    """
    if "ball_pressure_max_MPa" not in table:
        return {"ball_pressure_max_MPa": np.nan, "specimens_above_iso76": 0, "specimens_checked": 0}
    per = table[table["variant"] == key].groupby("specimen_id")["ball_pressure_max_MPa"].max().dropna()
    return {"ball_pressure_max_MPa": float(per.max()) if len(per) else np.nan,
            "specimens_above_iso76": int((per > ISO76_BALL_PRESSURE_MPA).sum()),
            "specimens_checked": int(len(per))}


def contact_check(table: pd.DataFrame, key: str) -> dict:
    """The solver's own check under variant ``key``: how far the tooth pairs, re-found from scratch
    at +-T, sink into each other. Returns ``max_penetration_redetected_um`` (the largest over the
    specimens that have it; a solve fails beyond ``hdwf.fe.relinearise.REDETECTED_LIMIT``) and
    ``specimens_contact_unchecked``: solved specimens without it (tables made before the column
    existed, or a coned cup, whose slices keep their settled gaps), so that no one reads the
    largest value as covering them."""
    rows = table[table["variant"] == key]
    solved = rows.groupby("specimen_id")["status"].agg(lambda st: bool((st == "ok").all()))
    if "max_penetration_redetected_um" not in rows:
        return {"max_penetration_redetected_um": float("nan"), "specimens_contact_unchecked": int(solved.sum())}
    per = rows.groupby("specimen_id")["max_penetration_redetected_um"].max()   # the same specimens as solved
    return {"max_penetration_redetected_um": float(per.max()) if per.notna().any() else float("nan"),
            "specimens_contact_unchecked": int((solved & per.isna()).sum())}


def solve_ladder(meas: Measurements, table: pd.DataFrame, rungs: list[tuple[str, dict]],
                 setup: SolveSetup) -> tuple[pd.DataFrame, int]:
    """The ladder from actual solves: every rung's variant is looked up in the specimens' tables
    and solved (mesh, wave generator and the missing variants only) where a table lacks it,
    i.e. for the found effects at their calibrated values.

    Parameters
    ----------
    meas : Measurements
        The checked measurements.
    table : pandas.DataFrame
        The campaign's tables.
    rungs : list of tuple
        ``(label, effects)`` (``ladder_variants``).
    setup : SolveSetup
        Drive, mesh settings, load steps and processes of the solves.

    Returns
    -------
    tuple
        The ladder (``ladder_table``) and the number of variant solves it needed.
    """
    have = table.groupby("specimen_id")["variant"].agg(set).to_dict()
    todo = {sid: [eff for _, eff in rungs if variant_key(eff) not in have.get(sid, set())]
            for sid in meas.specimens["specimen_id"]}
    need = meas.specimens[[bool(todo[sid]) for sid in meas.specimens["specimen_id"]]]
    if len(need):
        table = pd.concat([table, solve_specimens(setup, need, todo.__getitem__)], ignore_index=True)
    return ladder_table(meas, table, rungs), int(sum(len(v) for v in todo.values()))
