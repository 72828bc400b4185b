"""Stages of ``workflow/rules/stats.smk``: correlation, the quadratic surrogate and its Sobol' indices,
each written as an artefact with its figure."""

from __future__ import annotations

from dataclasses import asdict

import pandas as pd

from hdwf import PARAMETER_COLUMNS, PARAMETERS
from hdwf.common.io import read_json, write_json, write_parquet
from hdwf.report.figures import correlation_figure, sobol_convergence_figure, stamped, surrogate_figure
from hdwf.study.sobol import convergence, exact_indices
from hdwf.study.stats import correlation
from hdwf.study.surrogate import QuadraticSurrogate, fit_quadratic, rebound


def correlation_stage(lost_motion_path, out_parquet, out_png, title: str, provenance: dict) -> pd.DataFrame:
    """Correlation table (Parquet, regression summary in its metadata) and its figure."""
    designs = pd.read_parquet(lost_motion_path)
    table, summary = correlation(designs)
    write_parquet(table, out_parquet, provenance=provenance, meta={"ols": asdict(summary)})
    with stamped(provenance):
        correlation_figure(designs, table, title, out_png)
    return table


def surrogate_stage(lost_motion_path, out_json, out_png, bounds_source: str, table3: dict, title: str,
                    provenance: dict) -> QuadraticSurrogate:
    """Fit Eq. 11 on the designs with a result; ``bounds_source`` is ``table3`` (the study's
    bounds) or ``design_range`` (the span of the design points: the surrogate is then
    never integrated outside its data)."""
    designs = pd.read_parquet(lost_motion_path)
    ok = designs[designs["lost_motion_arcmin"].notna()]
    X = ok[list(PARAMETER_COLUMNS)].to_numpy(float)
    y = ok["lost_motion_arcmin"].to_numpy(float)
    if bounds_source == "table3":
        lower = [table3[p][0] for p in PARAMETERS]
        upper = [table3[p][1] for p in PARAMETERS]
    elif bounds_source == "design_range":
        lower, upper = X.min(axis=0), X.max(axis=0)
    else:
        raise ValueError(f"unknown bounds source '{bounds_source}': use table3 or design_range")
    model = fit_quadratic(X, y, lower, upper, bounds_source)
    model.extra["n_failed_designs"] = int(len(designs) - len(ok))
    write_json({**model.to_dict(), "provenance": provenance}, out_json)
    with stamped(provenance):
        surrogate_figure(ok, model.predict(X), title, out_png)
    return model


def sobol_stage(surrogate_json, out_parquet, out_png, samplers, settings: dict, title: str,
                provenance: dict, other_bounds: dict[str, tuple[list, list]] | None = None) -> pd.DataFrame:
    """Exact indices plus the convergence runs of each sampler; stopping status in the metadata.

    ``other_bounds`` (name -> (lower, upper)) adds the exact indices of the same polynomial
    over other input bounds to the metadata, to show how much the indices depend on them.
    """
    model = QuadraticSurrogate.from_dict(read_json(surrogate_json))
    frames, status = [exact_indices(model)], {}
    for sampler in samplers:
        est, st = convergence(model.predict_unit, model.parameters, sampler, **settings)
        frames.append(est)
        status[sampler] = st
    table = pd.concat(frames, ignore_index=True)
    other = {}
    for name, (lower, upper) in (other_bounds or {}).items():
        ex = exact_indices(rebound(model, lower, upper, name))
        other[name] = {"lower": list(lower), "upper": list(upper), "S1": dict(zip(ex.parameter, ex.S1)),
                       "ST": dict(zip(ex.parameter, ex.ST))}
    write_parquet(table, out_parquet, provenance=provenance,
                  meta={"convergence": status, "exact_other_bounds": other, "settings": settings, "bounds_source": model.bounds_source,
                        "lower": model.lower, "upper": model.upper})
    with stamped(provenance):
        sobol_convergence_figure(table, title, out_png)
    return table
