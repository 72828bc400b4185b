"""Measured values as one vector of observations, and the model's value of each.

Whatever the form of a measurement file (curve, phi or lost motion), the diagnosis compares
one column ``D`` of observations with the model's prediction of each (``predict``, from the
solved tables), point by point.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hdwf.validation.comparison import branches, comparison_points
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

    A curve point is compared with the model at its measured torque, on the branch of the
    same kind (``twist_along_test``), so a test logged at other torques, in other steps or run −T
    first meets the model where it was measured.

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
    """
    t = table[table["variant"] == variant]
    if t.empty:
        raise KeyError(f"variant {variant!r} is not in the table")
    obs = obs.reset_index(drop=True)   # positions, whatever the caller's index
    out = np.full(len(obs), np.nan)
    curves = {sid: g.sort_values("step") for sid, g in t.groupby("specimen_id", sort=False)}
    for sid, rows in obs.groupby("specimen_id", sort=False):
        g = curves.get(sid)
        if g is None:
            raise KeyError(f"specimen {sid!r} has no solve for variant {variant!r}")
        tw = g["twist_arcmin"].to_numpy(float)
        T = g["torque_Nm"].to_numpy(float)
        if not np.isfinite(tw).all():        # this variant's solve failed for this specimen
            continue
        is_twist = (rows["quantity"] == "twist").to_numpy()
        if is_twist.any():
            curve = rows[is_twist].sort_values("step", kind="stable")
            out[curve.index.to_numpy()] = twist_along_test(T, tw, curve["torque_Nm"].to_numpy(float))
        if (~is_twist).any():
            kp, km = int(np.nanargmax(T)), int(np.nanargmin(T))
            value = {"phi_plus": tw[kp], "phi_minus": -tw[km], "lost_motion": tw[kp] - tw[km]}
            out[rows.index[~is_twist].to_numpy()] = [value[q] for q in rows["quantity"][~is_twist]]
    return out


def twist_along_test(model_torque: np.ndarray, model_twist: np.ndarray, torque: np.ndarray) -> np.ndarray:
    """The model's twist along a measured test, whichever way it was loaded first.

    The model's test loads +T first, from a state leaning towards its first load (its
    zero-torque convention, docs/fe-model.md). The section and every effect are symmetric
    under a mirror through the major axis, which turns +T into −T, so the model's test run
    −T first is the mirror image of its own: a measured test whose first non-zero torque is
    negative is compared with ``-branch_twist(model, -torque)``.

    Parameters
    ----------
    model_torque, model_twist : numpy.ndarray
        The model's test 0 → +T → 0 → −T → 0, in its order.
    torque : numpy.ndarray
        One specimen's measured torques, in test order.

    Returns
    -------
    numpy.ndarray
        The model's twist at each measured point (``branch_twist``).
    """
    loaded = np.flatnonzero(torque)
    if loaded.size and torque[loaded[0]] < 0:
        return -branch_twist(model_torque, model_twist, -torque)
    return branch_twist(model_torque, model_twist, torque)


def branch_twist(model_torque: np.ndarray, model_twist: np.ndarray, torque: np.ndarray) -> np.ndarray:
    """The model's twist at measured torques, each on the branch it was measured on.

    Both tests are split into branches by ``comparison.branches`` (load± while |T| rises,
    unload± while it falls); a measured point takes the model's twist interpolated linearly in
    |T| on the model's branch of the same kind (from the point that starts it), so measured
    torques on the model's steps get the model's values exactly. Parameters as
    ``twist_along_test``.

    Returns
    -------
    numpy.ndarray
        The model's twist at each measured torque; a torque beyond the model's test torque takes
        the twist at the test torque (``measurements.schedule_problems`` refuses those first).
    """
    model_branch = np.asarray(branches(model_torque))
    measured_branch = np.asarray(branches(torque))
    out = np.full(len(torque), np.nan)
    for b in np.unique(measured_branch):
        idx = np.flatnonzero(model_branch == b)
        if idx.size == 0:
            raise ValueError(f"the model's test has no {b} branch")
        idx = np.concatenate([[idx[0] - 1], idx]) if idx[0] > 0 else idx
        x, y = np.abs(model_torque[idx]), model_twist[idx]
        order = np.argsort(x, kind="stable")
        mine = measured_branch == b
        out[mine] = np.interp(np.abs(torque[mine]), x[order], y[order])
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
