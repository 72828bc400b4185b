"""Sobol' sensitivity indices of the surrogate: estimated (SALib) and exact.

Estimates follow SALib's sample/analyze split: the base sample (LHS, Halton or Sobol',
from ``hdwf.study.doe``) of dimension 2k gives the matrices A and B, the radial matrices AB_i
are built in SALib's row order (A, AB_1..AB_k, B per base point) and
``SALib.analyze.sobol.analyze`` returns S1 and ST (Saltelli 2010 / Jansen estimators) with
bootstrap confidence intervals.  SALib draws all its resamples at once, N x resamples copies of
the sample (1.8 GB at N = 262 144 and 100 resamples), and gathers the resampled A and B again
for every parameter and estimator (14 of a 36 s job).  So the point estimates are SALib's and
the bootstrap is ``_bootstrap``, written here: SALib's resampling (its generator, seeded per chunk
of ``BOOTSTRAP_CHUNK`` resamples) and estimators, each resample's A, B and variance gathered
once, the same numbers to round-off (``tests/study/test_sobol.py``).  The half-width is SALib's
z · std over all resamples.  The exact indices of a quadratic come from its Legendre
expansion (background §5, Sudret 2008) and are the value the estimates converge to.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from SALib.analyze import sobol as salib_sobol
from scipy.stats import norm

from hdwf.study.doe import unit_sample
from hdwf.study.surrogate import QuadraticSurrogate

SOBOL_COLUMNS = ["parameter", "sampler", "n", "S1", "S1_conf", "ST", "ST_conf"]
BOOTSTRAP_CHUNK = 20   # resamples drawn at once (the memory grows with N x resamples)


def exact_quadratic_indices(coef_linear, coef_square, coef_interaction) -> tuple[np.ndarray, np.ndarray]:
    """First-order and total indices of f = c0 + Σ a_i u_i + Σ q_i u_i² + Σ_{i<j} r_ij u_i u_j,
    u_i independent uniform on [-1, 1].

    With P1(u) = u, P2(u) = (3u² - 1)/2 the terms are orthogonal: Var(a u) = a²/3,
    Var(q u²) = 4 q²/45, Var(r u_i u_j) = r²/9; ``coef_interaction`` is a k×k symmetric
    (or upper-triangular) matrix of r_ij.
    """
    a = np.asarray(coef_linear, float)
    q = np.asarray(coef_square, float)
    r = np.triu(np.asarray(coef_interaction, float), 1)
    r = r + r.T
    v_main = a ** 2 / 3.0 + 4.0 * q ** 2 / 45.0
    v_pair = r ** 2 / 9.0
    total_var = v_main.sum() + np.triu(v_pair, 1).sum()
    if total_var <= 0:
        raise ValueError("the function is constant: Sobol' indices are undefined")
    return v_main / total_var, (v_main + v_pair.sum(axis=1)) / total_var


def exact_indices(surrogate: QuadraticSurrogate) -> pd.DataFrame:
    _, a, q, r = surrogate.polynomial()
    s1, st = exact_quadratic_indices(a, q, r)
    return pd.DataFrame({"parameter": surrogate.parameters, "sampler": "exact", "n": 0, "S1": s1, "S1_conf": 0.0,
                         "ST": st, "ST_conf": 0.0}, columns=SOBOL_COLUMNS)


def radial_matrix(base: np.ndarray) -> np.ndarray:
    """Rows A, AB_1, …, AB_k, B for each point of a 2k-dimensional base sample (SALib's order)."""
    n, two_k = base.shape
    k = two_k // 2
    A, B = base[:, :k], base[:, k:]
    blocks = np.empty((n, k + 2, k))
    blocks[:, 0] = A
    for i in range(k):
        ab = A.copy()
        ab[:, i] = B[:, i]
        blocks[:, i + 1] = ab
    blocks[:, k + 1] = B
    return blocks.reshape(n * (k + 2), k)


def estimate_indices(model_unit, parameters: list[str], sampler: str, n: int, seed: int,
                     num_resamples: int = 100, conf_level: float = 0.95) -> pd.DataFrame:
    """SALib estimate of S1, ST of ``model_unit`` (a function of points in [0, 1)^k) with n base points."""
    k = len(parameters)
    base = unit_sample(sampler, n, 2 * k, seed)
    y = np.asarray(model_unit(radial_matrix(base)), float)
    problem = {"num_vars": k, "names": list(parameters), "bounds": [[0.0, 1.0]] * k}
    # (SALib's least bootstrap, 2 resamples: its half-widths are not used)
    point = salib_sobol.analyze(problem, y, calc_second_order=False, num_resamples=2, seed=seed)
    z = norm.ppf(0.5 + conf_level / 2.0)
    resampled = _bootstrap(y, k, n, num_resamples, seed)
    half = {name: z * resampled[name].std(axis=0, ddof=1) for name in ("S1", "ST")}
    return pd.DataFrame({"parameter": parameters, "sampler": sampler, "n": n, "S1": point["S1"],
                         "S1_conf": half["S1"], "ST": point["ST"], "ST_conf": half["ST"]},
                        columns=SOBOL_COLUMNS)


def _bootstrap(y: np.ndarray, k: int, n: int, num_resamples: int, seed: int) -> dict[str, np.ndarray]:
    """S1 and ST of each bootstrap resample (``num_resamples`` x k each), as
    ``SALib.analyze.sobol.analyze(..., seed=seed + 7919 i, keep_resamples=True)`` gives them
    for chunk i of ``_chunks(num_resamples)``: its normalised output, its resample indices and
    its estimators (Saltelli 2010 first order, Jansen total)."""
    y = (y - y.mean()) / y.std()
    radial = y.reshape(n, k + 2)
    A, B = radial[:, 0], radial[:, k + 1]
    out = {"S1": np.empty((num_resamples, k)), "ST": np.empty((num_resamples, k))}
    start = 0
    for i, size in enumerate(_chunks(num_resamples)):
        # (SALib leaves seed 0 unseeded; here every seed seeds)
        r = np.random.default_rng(seed + 7919 * i).integers(n, size=(n, size))
        Ar, Br = A[r], B[r]
        var = np.var(np.r_[Ar, Br], axis=0)
        rows = slice(start, start + size)
        for j in range(k):
            ABr = radial[:, j + 1][r]
            out["S1"][rows, j] = np.mean(Br * (ABr - Ar), axis=0) / var
            out["ST"][rows, j] = 0.5 * np.mean((Ar - ABr) ** 2, axis=0) / var
        start += size
    return out


def _chunks(num_resamples: int) -> list[int]:
    """``num_resamples`` split into chunks of at most ``BOOTSTRAP_CHUNK``, each of 2 or more (the
    chunks SALib was once called with, so the seeds and resamples stay the same)."""
    if num_resamples < 2:
        raise ValueError(f"num_resamples must be >= 2 (a standard deviation), not {num_resamples}")
    sizes = [BOOTSTRAP_CHUNK] * (num_resamples // BOOTSTRAP_CHUNK)
    rest = num_resamples - sum(sizes)
    if rest == 1:
        sizes[-1] += 1
    elif rest:
        sizes.append(rest)
    return sizes


def convergence(model_unit, parameters: list[str], sampler: str, *, n_start: int = 64, n_min: int = 65536,
                n_max: int = 262144, tolerance: float = 0.002, seed: int = 0, num_resamples: int = 100,
                conf_level: float = 0.95) -> tuple[pd.DataFrame, dict]:
    """Estimates at N = n_start, 2·n_start, … until converged.

    Converged means: N ≥ n_min and the largest change of any index since the previous N is
    below ``tolerance``. Stops at n_max otherwise and says so. Each N uses a fresh seeded
    sample (seed + log2 N), so successive estimates are independent and their change
    measures the error honestly. The bootstrap half-widths are reported for the last N only
    (NaN before it) and not used to stop: the bootstrap treats points as independent, which
    overstates the error of low-discrepancy (Halton, Sobol') samples several-fold, and it is
    97 % of the cost of an estimate.
    """
    frames, previous, status = [], None, None
    n = n_start

    def estimate(n, resamples):
        return estimate_indices(model_unit, parameters, sampler, n, seed + int(np.log2(n)), resamples, conf_level)

    while n <= n_max:
        est = estimate(n, 2)                 # point estimates; SALib needs >= 2 resamples
        est[["S1_conf", "ST_conf"]] = np.nan
        frames.append(est)
        vals = est[["S1", "ST"]].to_numpy()
        change = float(np.abs(vals - previous).max()) if previous is not None else np.inf
        previous = vals
        if n >= n_min and change < tolerance:
            status = {"converged": True, "n_converged": n, "max_change": change}
            break
        n *= 2
    if status is None:
        status = {"converged": False, "n_converged": None, "max_change": change,
                  "reason": f"tolerance {tolerance} not reached by n_max = {n_max}"}
    last = frames[-1]
    full = estimate(int(last["n"].iloc[0]), num_resamples)   # same sample: same point estimates
    frames[-1] = full
    status["max_conf"] = float(full[["S1_conf", "ST_conf"]].to_numpy().max())
    return pd.concat(frames, ignore_index=True), status
