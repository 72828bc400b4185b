"""Measured values as one vector of observations, and the model's value of each.

Whatever the form of a measurement file (curve, phi or lost motion), the diagnosis compares
one column ``D`` of observations with the model's prediction of each (``predict``, from the
solved tables), point by point.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hdwf.validation.comparison import comparison_points
from hdwf.validation.measurements import Measurements


def observation_frame(meas: Measurements) -> pd.DataFrame:
    """The measured values as one column of observations.

    Parameters
    ----------
    meas : Measurements
        A checked measurement file.

    Returns
    -------
    pandas.DataFrame
        ``D`` with its keys (``specimen_id`` [, ``step``, ``torque_Nm``]), ``quantity`` (twist,
        phi_plus, phi_minus or lost_motion) and ``u_D`` (NaN where the file states none).
    """
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
    """The model's value of every observation for one variant.

    Parameters
    ----------
    table : pandas.DataFrame
        Solved tables (``hdwf.validation.variants.TABLE_COLUMNS``).
    obs : pandas.DataFrame
        Observations (``observation_frame``).
    variant : str
        The variant's key (``variant_key``).

    Returns
    -------
    numpy.ndarray
        One value per observation; NaN where the variant's solve failed for that specimen.

    Raises
    ------
    KeyError
        When the variant, or a specimen's solve of it, is not in the table.
    ValueError
        When a measured step is not a step of the model's test.
    """
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


def prediction_points(obs: pd.DataFrame, S: np.ndarray) -> pd.DataFrame:
    """The observations against a prediction, as comparison points.

    Parameters
    ----------
    obs : pandas.DataFrame
        Observations (``observation_frame``).
    S : numpy.ndarray
        The model's value of each observation.

    Returns
    -------
    pandas.DataFrame
        ``hdwf.validation.comparison.comparison_points`` of the two (observations without a
        step are numbered in order).
    """
    return comparison_points(_measured_for_points(obs), _predicted_for_points(obs, S), "value")


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
