"""Values as strict JSON takes them: the diagnosis, the detectability plan and a surrogate's
leave-one-out error can hold NaN, inf and numpy scalars."""

from __future__ import annotations

import math

import numpy as np


def json_safe(obj):
    """A copy of ``obj`` that ``json.dumps`` writes as strict JSON.

    Parameters
    ----------
    obj : object
        Nested dicts, lists and tuples of numbers, strings, booleans and None.

    Returns
    -------
    object
        The same structure with NaN and inf as None, numpy scalars as Python numbers, tuples
        and arrays as lists and keys as strings.
    """
    if isinstance(obj, dict):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj
