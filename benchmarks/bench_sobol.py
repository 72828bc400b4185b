"""One Sobol' job: the three samplers' convergence runs on a study's surrogate (time and memory).

Fits the paper study's quadratic surrogate to Table 4 (HD 42) or Table 5 (HD 120), as the
``surrogate`` rule does, and runs ``hdwf.study.sobol.convergence`` for every sampler with the
default ``sobol`` settings of ``config.yaml``, as the ``sobol`` rule does (without its figure
and file). Prints each sampler's median time over the repeats, where it stopped, and the
process's peak resident memory. The LHS sampler does not converge and runs to ``n_max``,
where its point estimates and bootstrap set the time and the peak.

Run with one thread:  OMP_NUM_THREADS=1 python benchmarks/bench_sobol.py [--unit hd120] [--repeats 3]
"""

from __future__ import annotations

import argparse
import resource
import statistics
import time

import _one_thread  # noqa: F401  (first: one BLAS thread, hdwf importable)

from hdwf import PARAMETER_COLUMNS  # noqa: E402
from hdwf.config import load_config  # noqa: E402
from hdwf.study.paper import load_fea_designs  # noqa: E402
from hdwf.study.sobol import convergence  # noqa: E402
from hdwf.study.surrogate import fit_quadratic  # noqa: E402
from _workspace import ROOT  # noqa: E402


def main(unit: str, repeats: int) -> None:
    config = load_config(ROOT / "config.yaml")
    table = load_fea_designs(ROOT / config["paper_data"], unit)
    X = table[list(PARAMETER_COLUMNS)].to_numpy()
    model = fit_quadratic(X, table["lost_motion_arcmin"].to_numpy(), X.min(0), X.max(0), "design_range")
    settings = {k: v for k, v in config["sobol"].items() if k != "samplers"}
    total = 0.0
    for sampler in config["sobol"]["samplers"]:
        times, status = [], None
        for _ in range(repeats):
            t0 = time.perf_counter()
            _, status = convergence(model.predict_unit, model.parameters, sampler, **settings)
            times.append(time.perf_counter() - t0)
        stop = f"converged at N = {status['n_converged']}" if status["converged"] else "not converged by n_max"
        print(f"{unit} {sampler}: median {statistics.median(times):.2f} s of {repeats} ({stop})")
        total += statistics.median(times)
    peak_gb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 ** 2
    print(f"{unit}: the three samplers {total:.2f} s; peak resident memory {peak_gb:.2f} GB")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unit", choices=("hd42", "hd120"), default="hd42")
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    main(a.unit, a.repeats)
