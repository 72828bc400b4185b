"""The paper's statistics chain in the report (Part I, and the statistics of each FE study in
Part II): inputs and bounds, designs, correlation, quadratic surrogate, Sobol' indices and our
figures against the paper's published ones. Each section reads the artefacts it shows."""

from __future__ import annotations

import numpy as np
import pandas as pd

from hdwf import PARAMETER_COLUMNS, PARAMETERS
from hdwf.common.io import read_json, read_parquet_meta
from hdwf.report.artefacts import DriveArtefacts, StudyArtefacts
from hdwf.report.document import UNIT_NAMES, Document, fmt, lit, math_label
from hdwf.report.references import cite
from hdwf.study.doe import space_filling, to_unit
from hdwf.study.paper import load_bearings, load_bounds, load_drives, load_published

#: The base sample size at which the Sobol'-sequence estimate is held against the exact indices.
SOBOL_CHECK_N = 65536


def exact_sobol(sobol_path) -> pd.DataFrame:
    """The exact Sobol' indices of a study's surrogate.

    Parameters
    ----------
    sobol_path
        The study's ``sobol.parquet`` for one drive.

    Returns
    -------
    pandas.DataFrame
        Columns ``S1`` and ``ST`` indexed by parameter.
    """
    sob = pd.read_parquet(sobol_path)
    return sob[sob.sampler == "exact"].set_index("parameter")


def inputs_section(doc: Document, units: list[str], data_dir, level: int = 1) -> None:
    """The drives, their test torque and bearings, and the parameter bounds (paper Tables 1–3).

    Parameters
    ----------
    doc
        The document to add to.
    units
        The drives shown, in order.
    data_dir
        The paper's tables (config ``paper_data``).
    level
        Heading level of the section.
    """
    drives, bearings = load_drives(data_dir), load_bearings(data_dir)
    doc.heading("Inputs and bounds", level)
    doc.text("Both drives have $z_\"FS\" = 240$, $z_\"CS\" = 242$ (ratio −120). The test applies ±4 % of the "
             "rated torque $T_N$ to the flexspline with the wave generator locked and the circular spline fixed; "
             "lost motion $Phi = phi + phi'$ (paper, Eq. 1).")
    rows = []
    for u in units:
        d, b = drives.loc[u], bearings.loc[u]
        rows.append([UNIT_NAMES[u], fmt(d.T_N_Nm, 0), fmt(0.04 * d.T_N_Nm, 2), lit(b.bearing_type), fmt(b.d_mm, 2),
                     fmt(b.D_mm, 2), fmt(b.B_mm, 2)])
    doc.table(["drive", "$T_N$ (N·m)", "4 % $T_N$ (N·m)", "bearing", "$d$ (mm)", "$D$ (mm)", "$B$ (mm)"], rows,
              "The drives (paper Tables 1 and 2).")
    rows = []
    for u in units:
        b = load_bounds(data_dir, u)
        for limit in ("nominal", "minimal", "maximal"):
            rows.append([f"{UNIT_NAMES[u]} {limit}"] + [f"{b.loc[limit, c]:.3f}" for c in PARAMETER_COLUMNS])
    doc.table(["", *[f"{math_label(p)} (mm)" for p in PARAMETERS]], rows,
              "Parameter bounds of the study (paper Table 3).")


def _space_filling_rows(drive: DriveArtefacts) -> list[list[str]]:
    """The paper's design and our LHS of one drive, measured by the same space-filling criteria."""
    _, meta = read_parquet_meta(drive.doe)
    b = meta["bounds_mm"]
    lo, hi = [b[p][0] for p in PARAMETERS], [b[p][1] for p in PARAMETERS]
    lm = pd.read_parquet(drive.lost_motion)
    paper_unit = np.clip(to_unit(lm[list(PARAMETER_COLUMNS)].to_numpy(float), lo, hi), 0, 1)
    paper_sf = space_filling(paper_unit)
    ours_unit = to_unit(pd.read_parquet(drive.doe)[list(PARAMETER_COLUMNS)].to_numpy(float), lo, hi)
    ours = meta["space_filling"]
    name = UNIT_NAMES[drive.unit]
    return [[f"{name} paper design", fmt(paper_sf.centered_l2_discrepancy, 5),
             fmt(paper_sf.maximin_distance, 4), fmt(paper_sf.max_abs_correlation, 4), _least_covered(paper_unit)],
            [f"{name} our LHS (seed {meta['seed']})", fmt(ours["centered_l2_discrepancy"], 5),
             fmt(ours["maximin_distance"], 4), fmt(ours["max_abs_correlation"], 4), _least_covered(ours_unit)]]


def _least_covered(unit_points: np.ndarray) -> str:
    """The input whose design values span the least of its bounds, and that span (in the unit cube)."""
    lo, hi = unit_points.min(axis=0), unit_points.max(axis=0)
    i = int(np.argmin(hi - lo))
    return f"{math_label(PARAMETERS[i])}: {100 * lo[i]:.0f}–{100 * hi[i]:.0f} %"


def designs_section(doc: Document, study: StudyArtefacts, level: int = 1) -> None:
    """The design points with their lost motion, and the space-filling criteria of the designs.

    Parameters
    ----------
    doc
        The document to add to.
    study
        The study whose designs are shown.
    level
        Heading level of the section.
    """
    doc.heading("Designs", level)
    doc.text("The paper's 27 design points per drive (its Tables 4 and 5) with its Ansys FEA lost motion. Beside them, "
             "our own optimal Latin hypercube (scipy `LatinHypercube`, optimised for centered $L_2$ discrepancy, "
             "seeded), which later studies solve with our FE model; both are measured by the same space-filling "
             "criteria in the unit cube of the paper's Table 3 bounds.")
    for drive in study.drives:
        lm = pd.read_parquet(drive.lost_motion)
        rows = [[lit(r.design_id), *[fmt(getattr(r, c), 7) for c in PARAMETER_COLUMNS], fmt(r.lost_motion_arcmin, 4)]
                for r in lm.itertuples()]
        doc.table(["design", *[f"{math_label(p)} (mm)" for p in PARAMETERS], "$Phi$ (arcmin)"], rows,
                  f"{UNIT_NAMES[drive.unit]}: design points and lost motion ({len(lm)} designs).")
    rows = [row for drive in study.drives for row in _space_filling_rows(drive)]
    doc.table(["design", "centered $L_2$ discrepancy", "maximin distance", "max |r| between inputs",
               "least-covered input"], rows,
              "Space-filling criteria (unit cube of the paper's Table 3 bounds): lower discrepancy and correlation, larger "
              "distance are better; they depend only on the design's points in the unit cube, so one seeded "
              "hypercube scaled to both drives scores the same on each. Least-covered input: the input whose design values span the least of its "
              "bounds, and the span; a design that leaves part of a range empty scores a high discrepancy, and "
              "indices over the full bounds extrapolate its surrogate there.")


def correlation_section(doc: Document, study: StudyArtefacts, level: int = 1) -> None:
    """Pearson, Spearman and OLS of lost motion on each input, with the figure of each drive.

    Parameters
    ----------
    doc
        The document to add to.
    study
        The study whose correlation artefacts are shown.
    level
        Heading level of the section.
    """
    doc.heading("Correlation", level)
    doc.text(f"Multiple linear regression of $Phi$ on the five inputs (statsmodels OLS {cite('statsmodels')}; the standardised coefficient "
             "is $b dot s_x \\/ s_y$), Pearson's $r$ and Spearman's $rho$ with their p-values (scipy).")
    for drive in study.drives:
        name = UNIT_NAMES[drive.unit]
        corr = pd.read_parquet(drive.correlation)
        _, meta = read_parquet_meta(drive.correlation)
        ols = meta["ols"]
        rows = [[math_label(r.parameter), fmt(r.pearson_r), fmt(r.pearson_p, 3), fmt(r.spearman_rho),
                 fmt(r.spearman_p, 3), fmt(r.ols_coef, 3), fmt(r.ols_std_coef), fmt(r.ols_p, 3)]
                for r in corr.itertuples()]
        doc.table(["parameter", "Pearson $r$", "p", "Spearman $rho$", "p", "OLS $b$ (arcmin/mm)", "std. $b$", "p"],
                  rows, f"{name}: correlation of each input with $Phi$; OLS $R^2$ = {fmt(ols['r2'])}, "
                        f"adjusted {fmt(ols['r2_adj'])}, F-test p = {fmt(ols['f_pvalue'], 3)}, n = {ols['n']}.")
        doc.figure(drive.correlation_png,
                   f"{name}: $Phi$ against each input (circles), least-squares line (red, Pearson) and "
                   "best monotone fit (black, what Spearman measures); cf. the paper's Fig. 6/7.")


def _coefficient_rows(coef: dict[str, float]) -> list[list[str]]:
    """The surrogate's terms and coefficients in two pairs of columns."""
    terms = list(coef)
    half = (len(terms) + 1) // 2
    rows = []
    for i in range(half):
        left = [lit(terms[i]), fmt(coef[terms[i]], 5)]
        right = [lit(terms[i + half]), fmt(coef[terms[i + half]], 5)] if i + half < len(terms) else ["", ""]
        rows.append(left + right)
    return rows


def surrogate_section(doc: Document, study: StudyArtefacts, level: int = 1) -> None:
    """The quadratic surrogate (paper Eq. 11): its quality, coefficients and figure per drive.

    Parameters
    ----------
    doc
        The document to add to.
    study
        The study whose surrogates are shown.
    level
        Heading level of the section.
    """
    doc.heading("Quadratic surrogate", level)
    doc.text("The paper's Eq. 11: a full quadratic in the five inputs (21 terms) fitted by least squares on inputs "
             "scaled to $[-1, 1]$ over the bounds named below. $Q^2_\"LOO\"$ is the leave-one-out (PRESS) "
             "coefficient: it tells how well the surrogate predicts a design it was not fitted to. With 27 designs "
             "and 21 terms the fit has 6 residual degrees of freedom, so $R^2$ alone flatters it.")
    rows = []
    for drive in study.drives:
        s = read_json(drive.surrogate)
        rows.append([UNIT_NAMES[drive.unit], str(s["n"]), fmt(s["r2"]), fmt(s["r2_adj"]), fmt(s["q2_loo"]),
                     fmt(s["rmse"], 4), fmt(s["extra"]["max_leverage"], 3), s["bounds_source"].replace("_", " ")])
    doc.table(["drive", "n", "$R^2$", '$R^2_"adj"$', '$Q^2_"LOO"$', "RMSE (arcmin)", "max leverage", "bounds"],
              rows, "Surrogate quality.")
    for drive in study.drives:
        name = UNIT_NAMES[drive.unit]
        doc.table(["term", "coefficient (arcmin)", "term", "coefficient (arcmin)"],
                  _coefficient_rows(read_json(drive.surrogate)["coefficients_by_term"]),
                  f"{name}: surrogate coefficients in scaled inputs $u in [-1, 1]$.")
        doc.figure(drive.surrogate_png,
                   f"{name}: data (circles) and surrogate (asterisks) against each input, and parity; "
                   "cf. the paper's Fig. 8/9.")


def _sobol_rows(sob: pd.DataFrame, exact: pd.DataFrame) -> list[list[str]]:
    """Per parameter: the exact indices, then each sampler's estimate at its last N with its interval."""
    rows = []
    for p in PARAMETERS:
        row = [math_label(p), fmt(exact.loc[p, "S1"]), fmt(exact.loc[p, "ST"])]
        for sampler in ("lhs", "halton", "sobol"):
            sub = sob[(sob.sampler == sampler) & (sob.parameter == p)]
            if len(sub):
                last = sub[sub.n == sub.n.max()].iloc[0]
                row += [f"{fmt(last.S1)} ± {fmt(last.S1_conf, 3)}", f"{fmt(last.ST)} ± {fmt(last.ST_conf, 3)}"]
            else:
                row += ["–", "–"]
        rows.append(row)
    return rows


def _last_n(sob: pd.DataFrame) -> str:
    """Each sampler's last base sample size, e.g. ``LHS N = 2^18, Halton N = 2^16``."""
    names = {"lhs": "LHS", "halton": "Halton", "sobol": "Sobol'"}
    last = sob.groupby("sampler").n.max()
    return ", ".join(f"{names[s]} $N = 2^({int(np.log2(last[s]))})$" for s in names if s in last)


def _sobol_drive(doc: Document, drive: DriveArtefacts) -> None:
    """One drive's indices table, its check against the exact values, and its convergence figure."""
    name = UNIT_NAMES[drive.unit]
    sob = pd.read_parquet(drive.sobol)
    _, meta = read_parquet_meta(drive.sobol)
    exact = exact_sobol(drive.sobol)
    stop = "; ".join(f"{k}: " + (f"converged at N = {v['n_converged']}" if v["converged"]
                                 else f"not converged ({v['reason']})") for k, v in meta["convergence"].items())
    doc.table(["parameter", "exact $S_i$", "exact $S_(T i)$", "LHS $S_i$", "LHS $S_(T i)$", "Halton $S_i$",
               "Halton $S_(T i)$", "Sobol' $S_i$", "Sobol' $S_(T i)$"], _sobol_rows(sob, exact),
              f"{name}: indices, estimates at each sampler's last $N$ ({_last_n(sob)}); ± is the half-width of the "
              f"{100 * meta['settings'].get('conf_level', 0.95):g} % bootstrap interval. Stopping (largest change "
              f"between successive $N$ below {meta['settings']['tolerance']}, $N >=$ {meta['settings']['n_min']}; "
              f"a rule on the estimates' steps, not on the interval): {lit(stop)}.")
    sub = sob[(sob.sampler == "sobol") & (sob.n == SOBOL_CHECK_N)].set_index("parameter")
    if len(sub):
        params = list(PARAMETERS)
        err = max(float(np.max(np.abs(sub.loc[params, k].to_numpy() - exact.loc[params, k].to_numpy())))
                  for k in ("S1", "ST"))
        doc.text(f"{name}: the Sobol'-sequence estimate at $N = {SOBOL_CHECK_N}$ differs from the exact indices "
                 f"by at most {fmt(err, 5)}.")
    doc.figure(drive.sobol_png, f"{name}: convergence of $S_i$ (blue) and $S_(T i)$ (red) with $N$, one panel per "
               "input (dotted LHS, dashed Halton, solid Sobol'); thick pale lines are the exact values; cf. the paper's Figs. 13/14.")


def sobol_section(doc: Document, study: StudyArtefacts, level: int = 1) -> None:
    """Sobol' indices of the surrogate: exact values and each sampler's converging estimates.

    Parameters
    ----------
    doc
        The document to add to.
    study
        The study whose Sobol' artefacts are shown.
    level
        Heading level of the section.
    """
    doc.heading("Sobol' indices", level)
    doc.text("First-order $S_i$ and total-effect $S_(T i)$ indices of the surrogate over uniform inputs. Estimates: "
             f"SALib's {cite('salib')} Saltelli {cite('saltelli')} and Jansen {cite('jansen')} estimators on radial samples built from LHS, Halton and Sobol' base samples "
             "of growing size $N$ (powers of two), with 95 % bootstrap intervals at the last $N$. The *exact* "
             "values come from the Legendre expansion of the quadratic ($V_i = a_i^2\\/3 + 4 q_i^2\\/45$, "
             "$V_(i j) = r_(i j)^2\\/9$) and are what the estimates converge to.")
    for drive in study.drives:
        _sobol_drive(doc, drive)


def _ours(drive: DriveArtefacts, statistic: str, parameter) -> tuple[str, float, str]:
    """What a published statistic is, our value of it, and (Sobol' indices) ours over Table 3's bounds."""
    if statistic in ("spearman_rho", "ols_coef"):
        corr = pd.read_parquet(drive.correlation).set_index("parameter")
        what = {"spearman_rho": "Spearman $rho$", "ols_coef": "OLS coefficient (arcmin/mm)"}[statistic]
        return what, float(corr.loc[parameter, statistic]), "–"
    if statistic == "surrogate_r2":
        return "surrogate $R^2$", read_json(drive.surrogate)["r2"], "–"
    idx = statistic.split("_")[1]
    ours = float(exact_sobol(drive.sobol).loc[parameter, idx])
    _, meta = read_parquet_meta(drive.sobol)
    other = "–"
    if "table3" in meta.get("exact_other_bounds", {}):
        other = fmt(meta["exact_other_bounds"]["table3"][idx][parameter])
    return f"Sobol' {'$S_i$' if idx == 'S1' else '$S_(T i)$'} (exact)", ours, other


def _published_against_ours(study: StudyArtefacts, data_dir, statistic_prefix: str = "") -> list[tuple]:
    """Each statistic the paper publishes for the study's drives (starting ``statistic_prefix``):
    ``(published row, what it is, ours, ours over Table 3's bounds)``."""
    return [(r, *_ours(study.drive(r.unit), r.statistic, r.parameter)) for r in load_published(data_dir).itertuples()
            if r.unit in study.units and r.statistic.startswith(statistic_prefix)]


def _largest_sobol_difference(compared: list[tuple]) -> dict[str, float]:
    worst: dict[str, float] = {}
    for r, _, ours, _ in compared:
        if r.statistic.startswith("sobol_"):
            worst[r.unit] = max(worst.get(r.unit, 0.0), abs(ours - r.value))
    return worst


def largest_sobol_difference(study: StudyArtefacts, data_dir) -> dict[str, float]:
    """Per drive of ``study``, the largest |ours − published| over the Sobol' indices the paper publishes."""
    return _largest_sobol_difference(_published_against_ours(study, data_dir, "sobol_"))


def comparison_section(doc: Document, study: StudyArtefacts, data_dir, level: int = 1) -> None:
    """Every statistic the paper publishes beside ours, recomputed from its own tables.

    Parameters
    ----------
    doc
        The document to add to.
    study
        A study on the paper's tables (source ``paper``).
    data_dir
        The paper's tables (config ``paper_data``), with its published statistics.
    level
        Heading level of the section.
    """
    doc.heading("Our figures against the paper's", level)
    doc.text("Every statistic the paper publishes, recomputed here from its own Tables 4 and 5 (the paper's numbering). Differences are "
             "ours minus the paper's. Sobol' indices depend on the input bounds, which the paper does not state: "
             f"ours use *{study.surrogate_bounds.replace('_', ' ')}* bounds (the span of the "
             "design points, so the surrogate is never integrated where it has no data); the last column gives "
             "the exact indices over the paper's Table 3 bounds for comparison.")
    rows = []
    compared = _published_against_ours(study, data_dir)
    for r, what, ours, other in compared:
        rows.append([UNIT_NAMES[r.unit], what, math_label(r.parameter) if r.parameter else "", fmt(r.value),
                     fmt(ours), fmt(ours - r.value), other, lit(r.source)])
    doc.table(["drive", "statistic", "param.", "paper", "ours", "difference", "ours, paper Table 3 bounds", "paper source"],
              rows, "Replication of the paper's published statistics.")
    worst = _largest_sobol_difference(compared)
    if worst:
        doc.text("Largest difference of a Sobol' index from the paper's: " +
                 ", ".join(f"{UNIT_NAMES[u]} {fmt(v, 4)}" for u, v in worst.items()) + ".")
    doc.text("The paper's Sect. 8 quotes the influence of $d$ and $G_r$ as \"17.95 % to 17.09 %\" and "
             "\"20.23 % to 32.17 %\" (HD 42). The second figure of each pair is Spearman's $rho$; the first matches "
             "the OLS coefficient in arcmin per mm, which the paper reads as a percentage.")


def paper_part(doc: Document, study: StudyArtefacts, data_dir) -> None:
    """Part I of the full report: one study on the paper's tables, every section one level down.

    Parameters
    ----------
    doc
        The document to add to.
    study
        A study on the paper's tables (source ``paper``).
    data_dir
        The paper's tables (config ``paper_data``).
    """
    doc.heading(f"Part I — the paper's FEA tables (study '{study.name}')", 1)
    inputs_section(doc, study.units, data_dir, 2)
    designs_section(doc, study, 2)
    correlation_section(doc, study, 2)
    surrogate_section(doc, study, 2)
    sobol_section(doc, study, 2)
    comparison_section(doc, study, data_dir, 2)
    doc.pagebreak()
