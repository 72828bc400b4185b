"""The PDF report: a document model (headings, markup, tables, figures) assembled from the
artefacts alone, typeset by typst with its embedded fonts and a fixed date, so the same
artefacts give the same PDF on any machine."""

from __future__ import annotations

import json
import shutil
import tempfile
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd

from hdwf import PARAMETER_COLUMNS, PARAMETER_LABELS, PARAMETERS
from hdwf.common.io import atomic_path, read_json, read_parquet_meta
from hdwf.study.paper import load_bearings, load_bounds, load_drives, load_published

UNIT_NAMES = {"hd42": "HD 42", "hd120": "HD 120"}


def fmt(x, digits=4) -> str:
    """Numbers for tables: fixed digits, scientific when tiny or huge, an en dash for missing."""
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "–"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    x = float(x)
    if x != 0 and (abs(x) < 10 ** -(digits - 1) or abs(x) >= 1e6):
        return f"{x:.{max(digits - 2, 1)}e}"
    return f"{x:.{digits}f}"


_TYPST_SPECIAL = set("\\*_#$@<>`[]~")


def lit(text: str) -> str:
    """Escape literal text for typst markup (term names such as ``d*D`` or ``rFS^2``)."""
    return "".join("\\" + ch if ch in _TYPST_SPECIAL else ch for ch in str(text))


def _math_label(p: str) -> str:
    lab = PARAMETER_LABELS[p]
    if "_" in lab:
        base, sub = lab.split("_", 1)
        return f'${base}_"{sub}"$' if len(sub) > 1 else f"${base}_{sub}$"
    return f"${lab}$"


class Document:
    """A list of blocks that the typst template renders."""

    def __init__(self, title: str, subtitle: str, provenance: dict):
        self.title, self.subtitle, self.provenance = title, subtitle, provenance
        self.blocks: list[dict] = []
        self._figures: list[Path] = []

    def heading(self, text, level=1):
        """``text`` is plain text (typst shows it as it is), not markup: do not escape it."""
        self.blocks.append({"type": "heading", "level": level, "text": text})

    def text(self, markup: str):
        self.blocks.append({"type": "text", "text": markup})

    def table(self, columns: list[str], rows: list[list], caption: str):
        self.blocks.append({"type": "table", "columns": columns, "caption": caption,
                            "rows": [[c if isinstance(c, str) else fmt(c) for c in r] for r in rows]})

    def figure(self, path, caption: str, width: str = "100%"):
        name = f"fig{len(self._figures):02d}{Path(path).suffix}"
        self._figures.append(Path(path))
        self.blocks.append({"type": "figure", "path": name, "caption": caption, "width": width})

    def pagebreak(self):
        self.blocks.append({"type": "pagebreak"})

    def compile(self, out) -> Path:
        import typst

        template = resources.files("hdwf.report").joinpath("templates/report.typ").read_text()
        with tempfile.TemporaryDirectory(prefix="hdwf-report-") as build:
            build = Path(build)
            for i, src in enumerate(self._figures):
                shutil.copyfile(src, build / f"fig{i:02d}{src.suffix}")
            (build / "doc.json").write_text(json.dumps({"title": self.title, "subtitle": self.subtitle,
                                                        "provenance": self.provenance, "blocks": self.blocks}))
            (build / "report.typ").write_text(template)
            with atomic_path(out) as tmp:
                # Embedded fonts only and a fixed timestamp: identical PDFs on every machine.
                typst.compile(str(build / "report.typ"), output=str(tmp), root=str(build),
                              ignore_system_fonts=True, timestamp=0)
        return Path(out)


# --------------------------------------------------------------------------- paper study

def _inputs_section(doc: Document, units, data_dir, study_config, level: int = 1):
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
            rows.append([f"{UNIT_NAMES[u]} {limit}"] + [fmt(b.loc[limit, c], 3) for c in PARAMETER_COLUMNS])
    doc.table(["", *[f"{_math_label(p)} (mm)" for p in PARAMETERS]], rows,
              "Parameter bounds of the study (paper Table 3).")


def _designs_section(doc: Document, units, files, level: int = 1):
    from hdwf.study.doe import space_filling, to_unit

    doc.heading("Designs", level)
    doc.text("The paper's 27 design points per drive (Tables 4 and 5) with its Ansys FEA lost motion. Beside them, "
             "our own optimal Latin hypercube (scipy `LatinHypercube`, optimised for centered $L_2$ discrepancy, "
             "seeded), which later studies solve with our FE model; both are measured by the same space-filling "
             "criteria in the unit cube of Table 3's bounds.")
    for u in units:
        lm = pd.read_parquet(files[f"{u}__lost_motion"])
        rows = [[lit(r.design_id), *[fmt(getattr(r, c), 7) for c in PARAMETER_COLUMNS], fmt(r.lost_motion_arcmin, 4)]
                for r in lm.itertuples()]
        doc.table(["design", *[f"{_math_label(p)} (mm)" for p in PARAMETERS], "$Phi$ (arcmin)"], rows,
                  f"{UNIT_NAMES[u]}: design points and lost motion ({len(lm)} designs).")
    rows = []
    for u in units:
        _, meta = read_parquet_meta(files[f"{u}__doe"])
        b = meta["bounds_mm"]
        lo, hi = [b[p][0] for p in PARAMETERS], [b[p][1] for p in PARAMETERS]
        lm = pd.read_parquet(files[f"{u}__lost_motion"])
        paper_sf = space_filling(np.clip(to_unit(lm[list(PARAMETER_COLUMNS)].to_numpy(float), lo, hi), 0, 1))
        ours = meta["space_filling"]
        rows.append([f"{UNIT_NAMES[u]} paper design", fmt(paper_sf.centered_l2_discrepancy, 5),
                     fmt(paper_sf.maximin_distance, 4), fmt(paper_sf.max_abs_correlation, 4)])
        rows.append([f"{UNIT_NAMES[u]} our LHS (seed {meta['seed']})", fmt(ours["centered_l2_discrepancy"], 5),
                     fmt(ours["maximin_distance"], 4), fmt(ours["max_abs_correlation"], 4)])
    doc.table(["design", "centered $L_2$ discrepancy", "maximin distance", "max |r| between inputs"], rows,
              "Space-filling criteria (unit cube of Table 3 bounds): lower discrepancy and correlation, larger "
              "distance are better.")


def _correlation_section(doc: Document, units, files, level: int = 1):
    doc.heading("Correlation", level)
    doc.text("Multiple linear regression of $Phi$ on the five inputs (statsmodels OLS; the standardised coefficient "
             "is $b dot s_x \\/ s_y$), Pearson's $r$ and Spearman's $rho$ with their p-values (scipy).")
    for u in units:
        corr = pd.read_parquet(files[f"{u}__correlation"])
        _, meta = read_parquet_meta(files[f"{u}__correlation"])
        ols = meta["ols"]
        rows = [[_math_label(r.parameter), fmt(r.pearson_r), fmt(r.pearson_p, 3), fmt(r.spearman_rho),
                 fmt(r.spearman_p, 3), fmt(r.ols_coef, 3), fmt(r.ols_std_coef), fmt(r.ols_p, 3)]
                for r in corr.itertuples()]
        doc.table(["parameter", "Pearson $r$", "p", "Spearman $rho$", "p", "OLS $b$ (arcmin/mm)", "std. $b$", "p"],
                  rows, f"{UNIT_NAMES[u]}: correlation of each input with $Phi$; OLS $R^2$ = {fmt(ols['r2'])}, "
                        f"adjusted {fmt(ols['r2_adj'])}, F-test p = {fmt(ols['f_pvalue'], 3)}, n = {ols['n']}.")
        doc.figure(files[f"{u}__correlation_png"],
                   f"{UNIT_NAMES[u]}: $Phi$ against each input (circles), least-squares line (red, Pearson) and "
                   "best monotone fit (black, what Spearman measures); cf. the paper's Fig. 6/7.")


def _surrogate_section(doc: Document, units, files, level: int = 1):
    doc.heading("Quadratic surrogate", level)
    doc.text("The paper's Eq. 11: a full quadratic in the five inputs (21 terms) fitted by least squares on inputs "
             "scaled to $[-1, 1]$ over the bounds named below. $Q^2_\"LOO\"$ is the leave-one-out (PRESS) "
             "coefficient: it tells how well the surrogate predicts a design it was not fitted to. With 27 designs "
             "and 21 terms the fit has 6 residual degrees of freedom, so $R^2$ alone flatters it.")
    rows = []
    for u in units:
        s = read_json(files[f"{u}__surrogate"])
        rows.append([UNIT_NAMES[u], str(s["n"]), fmt(s["r2"]), fmt(s["r2_adj"]), fmt(s["q2_loo"]), fmt(s["rmse"], 4),
                     fmt(s["extra"]["max_leverage"], 3), s["bounds_source"].replace("_", " ")])
    doc.table(["drive", "n", "$R^2$", '$R^2_"adj"$', '$Q^2_"LOO"$', "RMSE (arcmin)", "max leverage", "bounds"],
              rows, "Surrogate quality.")
    for u in units:
        s = read_json(files[f"{u}__surrogate"])
        coef = s["coefficients_by_term"]
        terms = list(coef)
        half = (len(terms) + 1) // 2
        rows = []
        for i in range(half):
            left = [lit(terms[i]), fmt(coef[terms[i]], 5)]
            right = [lit(terms[i + half]), fmt(coef[terms[i + half]], 5)] if i + half < len(terms) else ["", ""]
            rows.append(left + right)
        doc.table(["term", "coefficient (arcmin)", "term", "coefficient (arcmin)"], rows,
                  f"{UNIT_NAMES[u]}: surrogate coefficients in scaled inputs $u in [-1, 1]$.")
        doc.figure(files[f"{u}__surrogate_png"],
                   f"{UNIT_NAMES[u]}: data (circles) and surrogate (asterisks) against each input, and parity; "
                   "cf. the paper's Fig. 8/9.")


def _sobol_section(doc: Document, units, files, level: int = 1):
    doc.heading("Sobol' indices", level)
    doc.text("First-order $S_i$ and total-effect $S_(T i)$ indices of the surrogate over uniform inputs. Estimates: "
             "SALib's Saltelli/Jansen estimators on radial samples built from LHS, Halton and Sobol' base samples "
             "of growing size $N$ (powers of two), with 95 % bootstrap intervals at the last $N$. The *exact* values come from "
             "the Legendre expansion of the quadratic ($V_i = a_i^2\\/3 + 4 q_i^2\\/45$, $V_(i j) = r_(i j)^2\\/9$) "
             "and are what the estimates converge to.")
    for u in units:
        sob = pd.read_parquet(files[f"{u}__sobol"])
        _, meta = read_parquet_meta(files[f"{u}__sobol"])
        exact = sob[sob.sampler == "exact"].set_index("parameter")
        rows = []
        for p in PARAMETERS:
            row = [_math_label(p), fmt(exact.loc[p, "S1"]), fmt(exact.loc[p, "ST"])]
            for sampler in ("lhs", "halton", "sobol"):
                sub = sob[(sob.sampler == sampler) & (sob.parameter == p)]
                if len(sub):
                    last = sub[sub.n == sub.n.max()].iloc[0]
                    row += [f"{fmt(last.S1)} ± {fmt(last.S1_conf, 3)}", f"{fmt(last.ST)} ± {fmt(last.ST_conf, 3)}"]
                else:
                    row += ["–", "–"]
            rows.append(row)
        conv = meta["convergence"]
        stop = "; ".join(f"{k}: " + (f"converged at N = {v['n_converged']}" if v["converged"]
                                     else f"not converged ({v['reason']})") for k, v in conv.items())
        doc.table(["parameter", "exact $S_i$", "exact $S_(T i)$", "LHS $S_i$", "LHS $S_(T i)$", "Halton $S_i$",
                   "Halton $S_(T i)$", "Sobol' $S_i$", "Sobol' $S_(T i)$"], rows,
                  f"{UNIT_NAMES[u]}: indices, estimates at each sampler's last $N$. Stopping (largest change "
                  f"between successive $N$ below {meta['settings']['tolerance']}, $N >=$ {meta['settings']['n_min']}): "
                  f"{lit(stop)}.")
        n_cmp = 65536
        sub = sob[(sob.sampler == "sobol") & (sob.n == n_cmp)].set_index("parameter")
        if len(sub):
            err = max(float(np.max(np.abs(sub.loc[list(PARAMETERS), k].to_numpy() - exact.loc[list(PARAMETERS), k].to_numpy())))
                      for k in ("S1", "ST"))
            doc.text(f"{UNIT_NAMES[u]}: the Sobol'-sequence estimate at $N = {n_cmp}$ differs from the exact indices "
                     f"by at most {fmt(err, 5)}.")
        doc.figure(files[f"{u}__sobol_png"], f"{UNIT_NAMES[u]}: convergence of $S_i$ and $S_(T i)$ with $N$ "
                   "(dotted LHS, dashed Halton, solid Sobol'); thick pale lines are the exact values; cf. Figs. 13/14.")


def _comparison_section(doc: Document, units, files, data_dir, study_config, level: int = 1):
    pub = load_published(data_dir)
    doc.heading("Our figures against the paper's", level)
    doc.text("Every statistic the paper publishes, recomputed here from its own Tables 4 and 5. Differences are "
             "ours minus the paper's. Sobol' indices depend on the input bounds, which the paper does not state: "
             f"ours use *{study_config.get('surrogate_bounds', 'table3').replace('_', ' ')}* bounds (the span of the "
             "design points, so the surrogate is never integrated where it has no data); the last column gives "
             "the exact indices over Table 3's bounds for comparison.")
    rows = []
    worst = {}
    for r in pub.itertuples():
        if r.unit not in units:
            continue
        u, stat, p = r.unit, r.statistic, r.parameter
        other = "–"
        if stat in ("spearman_rho", "ols_coef"):
            corr = pd.read_parquet(files[f"{u}__correlation"]).set_index("parameter")
            ours = float(corr.loc[p, stat])
            what = {"spearman_rho": "Spearman $rho$", "ols_coef": "OLS coefficient (arcmin/mm)"}[stat]
        elif stat == "surrogate_r2":
            ours = read_json(files[f"{u}__surrogate"])["r2"]
            what = "surrogate $R^2$"
        else:
            idx = stat.split("_")[1]
            sob = pd.read_parquet(files[f"{u}__sobol"])
            ours = float(sob[(sob.sampler == "exact")].set_index("parameter").loc[p, idx])
            _, meta = read_parquet_meta(files[f"{u}__sobol"])
            if "table3" in meta.get("exact_other_bounds", {}):
                other = fmt(meta["exact_other_bounds"]["table3"][idx][p])
            what = f"Sobol' {'$S_i$' if idx == 'S1' else '$S_(T i)$'} (exact)"
            worst[u] = max(worst.get(u, 0.0), abs(ours - r.value))
        rows.append([UNIT_NAMES[u], what, _math_label(p) if p else "", fmt(r.value), fmt(ours), fmt(ours - r.value),
                     other, lit(r.source)])
    doc.table(["drive", "statistic", "param.", "paper", "ours", "difference", "ours, Table 3 bounds", "paper source"],
              rows, "Replication of the paper's published statistics.")
    if worst:
        doc.text("Largest difference of a Sobol' index from the paper's: " +
                 ", ".join(f"{UNIT_NAMES[u]} {fmt(v, 4)}" for u, v in worst.items()) + ".")
    doc.text("The paper's Sect. 8 quotes the influence of $d$ and $G_r$ as \"17.95 % to 17.09 %\" and "
             "\"20.23 % to 32.17 %\" (HD 42). The second figure of each pair is Spearman's $rho$; the first matches "
             "the OLS coefficient in arcmin per mm, which the paper reads as a percentage.")


def study_report(study: str, units: list[str], files: dict[str, str], data_dir, study_config: dict,
                 provenance: dict, out) -> Path:
    """Typeset ``results/{study}/report.pdf`` from the study's artefacts."""
    source = study_config.get("source", "paper")
    subtitle = {"paper": "The statistics chain on the paper's own FEA tables (Tables 4 and 5)"}.get(source, source)
    doc = Document(f"hdwf study '{study}': lost motion of harmonic drives", subtitle, provenance)
    doc.text("This report reproduces the correlation, surrogate and global-sensitivity analysis of Majchrák et al., "
             "*Global Sensitivity Analysis of Chosen Harmonic Drive Parameters Affecting Its Lost Motion*, for the "
             f"drives {', '.join(UNIT_NAMES[u] for u in units)}. Every number and figure below was computed by the "
             "workflow from the artefacts under `results/`; the provenance above identifies the configuration, "
             "code and packages.")
    _inputs_section(doc, units, data_dir, study_config)
    _designs_section(doc, units, files)
    doc.pagebreak()
    _correlation_section(doc, units, files)
    doc.pagebreak()
    _surrogate_section(doc, units, files)
    doc.pagebreak()
    _sobol_section(doc, units, files)
    doc.pagebreak()
    _comparison_section(doc, units, files, data_dir, study_config)
    return doc.compile(out)


# --------------------------------------------------------------------------- FE parts

def _sub(files: dict[str, str], study: str) -> dict[str, str]:
    """The files of one study, keyed ``{unit}__{key}`` as the section functions expect."""
    prefix = f"{study}__"
    return {k[len(prefix):]: v for k, v in files.items() if k.startswith(prefix)}


def _fe_model_section(doc: Document, assumptions: list[dict] | None, pictures: dict[str, str] | None = None,
                      fe_settings: dict | None = None, level: int = 1):
    doc.heading("The FE model", level)
    doc.text("A 2D plane-stress section of each drive (gmsh mesh, scikit-fem assembly, linear-elastic steel, "
             "$E = 210$ GPa, $nu = 0.3$, thickness = face width) with unilateral frictionless contact between the "
             "locked wave-generator cam and the bearing inner ring, the balls and both raceways (radial clearance "
             "$G_r$), the outer ring and the flexspline bore (fit from $D$) and the flexspline and circular-spline "
             "tooth flanks. The circular spline is held at its outer rim; the test torque acts on the flexspline. "
             "The contact solver is our own (see `hdwf.fe`).")
    if fe_settings:
        half = fe_settings.get("symmetry", "full") == "half"
        doc.text(f"Settings: {fe_settings['elements_over_height']} elements over the tooth height and "
                 f"{fe_settings['elements_over_thickness']} over its thickness (the paper's rule) times a refinement "
                 f"of {fe_settings['refinement']:g}; {fe_settings['steps_per_ramp']} load steps per ramp; "
                 + ("the half model (angles 0 to π tied by the drive's 180° point symmetry, which reproduces the "
                    "full model's $Phi$ within 0.05 %, `docs/fe-model.md`)." if half else "the full model."))
    if assumptions:
        rows = [[lit(a["unit"]), lit(a["name"]), lit(a["value"]), lit(a["source"])] for a in assumptions]
        doc.table(["drive", "quantity", "value", "source or reason"], rows,
                  "Every value the paper does not give, with its source (`hdwf.drive.geometry`).")
    for label, path in (pictures or {}).items():
        doc.figure(path, f"{label}: the FS (left) and CS (right) teeth at the major axis at +4 % $T_N$, true scale; "
                   "colour: deformation added by the test torque with each body's rotation removed. The white "
                   "gaps are the clearance that $r_\"FS\"$ and $r_\"CS\"$ open.", width="75%")


def _convergence_section(doc: Document, units, files, level: int = 1):
    doc.heading("Mesh convergence", level)
    doc.text("The designs of the `fe` study are solved on other meshes too (element density factors below): every "
             "design on the two finest, representative designs also on the third. The grid convergence index (Celik et al. 2008) uses the tooth element size "
             "as the mesh size; *change* is the relative difference of $Phi$ between the two finest meshes, "
             "required below 2 %.")
    for u in units:
        conv = pd.read_parquet(files[f"{u}__convergence"])
        levels = ("fine", "medium", "coarse")
        rows = []
        for r in conv.to_dict("records"):
            rows.append([lit(r["design_id"]), *[fmt(r.get(f"phi_{k}_arcmin"), 4) for k in levels],
                         fmt(r.get("rel_change_fine", np.nan) * 100, 2),
                         fmt(r.get("gci_fine", np.nan) * 100, 2) + ("\\*" if r.get("asymptotic") is False else ""),
                         fmt(r.get("order_p"), 2), "yes" if r["converged"] else "*no*"])
        first = conv.iloc[0]
        heads = [f"$Phi$ at {first.get(f'refinement_{k}', np.nan):g}×" for k in levels]
        n_ok = int(conv["converged"].sum())
        doc.table(["design", *heads, "change (%)", "GCI (%)", "order $p$", "< 2 %"], rows,
                  f"{UNIT_NAMES[u]}: $Phi$ (arcmin) on three meshes (every design on the two finest, representative "
                  f"designs also on the coarsest, which gives the GCI); {n_ok} of {len(conv)} designs converged; "
                  f"largest change {fmt(conv['rel_change_fine'].max() * 100, 2)} %, median GCI "
                  f"{fmt(conv['gci_fine'].median() * 100 if 'gci_fine' in conv else np.nan, 2)} %. \\* no order of "
                  "convergence in [0.5, 10] fits the three values (pre-asymptotic or oscillating): GCI with safety "
                  "factor 3 and first order.")


def _curves_section(doc: Document, units, files, tmp: Path, level: int = 1):
    from hdwf.report.figures import curves_figure

    doc.heading("Torque–twist curves", level)
    for u in units:
        lm = pd.read_parquet(files[f"{u}__lost_motion"])
        ok = lm[lm["lost_motion_arcmin"].notna()].sort_values("lost_motion_arcmin")
        if ok.empty:
            continue
        picks = list(dict.fromkeys([ok.iloc[0].design_id, ok.iloc[len(ok) // 2].design_id, ok.iloc[-1].design_id]))
        path = tmp / f"curves_{u}.png"
        curves_figure(pd.read_parquet(files[f"{u}__curves"]), lm, picks, f"{UNIT_NAMES[u]}: smallest, median and "
                      "largest Φ of the fe study", path)
        doc.figure(path, f"{UNIT_NAMES[u]}: torque–twist curves of the test 0 → +4 % → 0 → −4 % → 0 $T_N$ for three "
                   "designs.", width="70%")
        failed = lm[lm["lost_motion_arcmin"].isna()]
        timing = (f"Solve time per design: median {fmt(lm['solve_s'].median(), 1)} s, largest "
                  f"{fmt(lm['solve_s'].max(), 1)} s; one factorisation {fmt(lm['factorize_s'].median(), 2)} s; "
                  f"ratio solve/factorise median {fmt((lm['solve_s'] / lm['factorize_s']).median(), 1)}.")
        doc.text(f"{UNIT_NAMES[u]}: {len(lm) - len(failed)} of {len(lm)} designs solved"
                 + (f"; failed: {lit(', '.join(failed.design_id))} ({lit(failed.iloc[0].status)})" if len(failed) else "")
                 + f". Teeth in contact at the test torque: {int(lm['teeth_in_contact'].min())}–"
                   f"{int(lm['teeth_in_contact'].max())}; largest penetration {fmt(lm['max_penetration_um'].max(), 4)} µm. "
                 + timing)


def _agreement_section(doc: Document, units, paper_files, ours_files, tmp: Path, level: int = 1):
    from scipy import stats as st

    from hdwf.report.figures import agreement_figure

    doc.heading("Our FE against the paper's FEA at its own design points", level)
    rows, pairs = [], {}
    for u in units:
        paper = pd.read_parquet(paper_files[f"{u}__lost_motion"]).set_index("design_id")["lost_motion_arcmin"]
        ours = pd.read_parquet(ours_files[f"{u}__lost_motion"]).set_index("design_id")["lost_motion_arcmin"]
        both = pd.concat({"paper": paper, "ours": ours}, axis=1).dropna()
        rho = st.spearmanr(both["paper"], both["ours"])
        r = st.pearsonr(both["paper"], both["ours"])
        ratio = both["ours"] / both["paper"]
        pairs[UNIT_NAMES[u]] = (paper.reindex(ours.index).to_numpy(float), ours.to_numpy(float))
        rows.append([UNIT_NAMES[u], str(len(both)), fmt(rho.statistic), fmt(rho.pvalue, 3), fmt(r.statistic ** 2),
                     fmt(both["paper"].mean(), 3), fmt(both["ours"].mean(), 3), fmt(ratio.median(), 2),
                     f"{fmt(ratio.min(), 2)}–{fmt(ratio.max(), 2)}"])
    doc.table(["drive", "n", "Spearman $rho$", "p", "$R^2$", "paper mean $Phi$", "our mean $Phi$",
               "median ratio ours/paper", "ratio range"], rows,
              "Agreement of our $Phi$ with the paper's at the 27 design points of Tables 4/5 ($R^2$ of a linear fit).")
    path = tmp / "agreement.png"
    agreement_figure(pairs, "hdwf FE vs the paper's Ansys FEA, same 27 designs", path)
    doc.figure(path, "Our lost motion against the paper's at the same design points.",
               width="100%" if len(pairs) > 1 else "55%")
    doc.text("The ranking is what the study needs (which parameters matter); the level differs by the median ratio "
             "above. Our 2D section has rigid-body flank backlash from $r_\"FS\"$, $r_\"CS\"$ with little preload "
             "to take it up; the paper's 3D model evidently takes most of it up.")


def _indices_vs_paper_section(doc: Document, units, data_dir, studies_files: dict[str, dict], level: int = 1):
    pub = load_published(data_dir)
    doc.heading("Sensitivity: our FE studies beside the paper", level)
    for u in units:
        rows = []
        for p in PARAMETERS:
            row = [_math_label(p)]
            for idx in ("S1", "ST"):
                v = pub[(pub.unit == u) & (pub.statistic == f"sobol_{idx}") & (pub.parameter == p)]["value"]
                row.append(fmt(float(v.iloc[0])) if len(v) else "–")
            for study, files in studies_files.items():
                sob = pd.read_parquet(files[f"{u}__sobol"])
                ex = sob[sob.sampler == "exact"].set_index("parameter")
                row += [fmt(ex.loc[p, "S1"]), fmt(ex.loc[p, "ST"])]
            rows.append(row)
        heads = ["param.", "paper $S_i$", "paper $S_(T i)$"]
        for study in studies_files:
            heads += [f"{lit(study)} $S_i$", f"{lit(study)} $S_(T i)$"]
        doc.table(heads, rows, f"{UNIT_NAMES[u]}: exact Sobol' indices of each study's quadratic surrogate beside the "
                               "paper's published values.")
        rows = []
        for study, files in studies_files.items():
            corr = pd.read_parquet(files[f"{u}__correlation"]).set_index("parameter")
            s = read_json(files[f"{u}__surrogate"])
            rows.append([lit(study), *[fmt(corr.loc[p, "spearman_rho"], 3) for p in PARAMETERS], fmt(s["r2"], 4),
                         fmt(s["q2_loo"], 4)])
        doc.table(["study", *[f"$rho$ {_math_label(p)}" for p in PARAMETERS], "surrogate $R^2$", "$Q^2_\"LOO\"$"],
                  rows, f"{UNIT_NAMES[u]}: Spearman $rho$ of each input with $Phi$ and surrogate quality per study.")


def _effect_sentence(r: dict) -> str:
    from hdwf.validation.effects import get as get_effect

    eff = get_effect(r["effect"])
    (pname, val), = r["params"].items()
    p = eff.param(pname)
    sd = r.get("param_sd")
    value = f"{fmt(val, 4)}" + (f" ± {fmt(sd, 2)}" if sd is not None else "") + f" {lit(p.unit)}"
    return f"*{lit(eff.title)}* ({lit(pname)} = {value})"


def _detectability_part(doc: Document, diag: dict, level: int):
    """Which candidates this data could have shown at all (diagnosis.json: detectability)."""
    det = diag.get("detectability")
    if not det:
        return
    from hdwf.validation.effects import get as get_effect

    doc.heading("What this data could show", level)
    rows = []
    for c in det["candidates"]:
        sd = c["expected_rel_sd"]
        rows.append([lit(c["effect"]), f"{c['realistic']:g} {lit(c['unit'])}",
                     fmt(c["change_rms_arcmin"], 3), fmt(c["change_max_arcmin"], 3),
                     fmt(c["noise_to_show_arcmin"], 3), fmt(c["noise_to_calibrate_arcmin"], 3),
                     fmt(c["expected_delta_bic"], 1),
                     "–" if sd is None else "> 1000 %" if sd > 10 else f"{fmt(100 * sd, 2)} %",
                     "yes" if c["visible"] else "no"])
    doc.table(["effect", "realistic value", "change RMS", "change max", "noise to show", "noise to calibrate",
               "ΔBIC", "sd of parameter", "visible"], rows,
              f"Each candidate at a realistic value, against a noise of {fmt(det['noise_arcmin'], 4)} arcmin per value "
              f"({lit(det['noise_from'])}). Change: what the effect does to the predictions (arcmin). Noise to show: the "
              "largest noise at which it would still pay (ΔBIC ≤ −10); noise to calibrate: at which its parameter would "
              "come out within 15 % (two standard deviations). ΔBIC and sd: what this data would give if the effect "
              "were there at that value (linearised).")
    hidden = [c for c in det["candidates"] if c["effect"] in diag["verdict"].get("could_not_see", [])]
    if hidden:
        doc.text("This data could not have shown these effects at realistic values, so its verdict says nothing "
                 "about them (not finding them is no evidence that they are absent): " + "; ".join(
            f"{lit(get_effect(c['effect']).title)} (it changes the predictions by {fmt(c['change_rms_arcmin'], 2)} "
            f"arcmin RMS and needs noise below {fmt(c['noise_to_show_arcmin'], 2)} arcmin)" for c in hidden)
            + (". Less noise (averaged repeat runs, a finer encoder), more readings per curve or more specimens "
               "would show them: a parameter's sd falls with the square root of the number of independent readings."
               if diag.get("noise_arcmin") else
               ". No noise is stated, so the final model's residual stands in for it; that residual also holds "
               "whatever error the model cannot explain, and a large model error hides every candidate until it "
               "is explained."))


def _refinement_part(doc: Document, diag: dict):
    """Which found effects the diagnosis re-solved before a further round, and where."""
    for name, r in diag.get("refinement", {}).items():
        if r.get("solved_at"):
            at = ", ".join(f"{v:.6g}" for v in r["solved_at"])
            doc.text(f"Before round {r['before_round']}, {lit(name)} was recalibrated on actual FE solves of every "
                     f"specimen at {lit(r['param'])} = {at} (solve {r['solves']}), so that round weighs its candidates "
                     "against the FE model, not against the interpolation error of the tabulated values.")
        if r["status"] in ("failed", "unsettled"):
            doc.text(f"Caution, {lit(name)}: {lit(r['reason'])}.")


def _validation_section(doc: Document, campaign: str, files: dict, level: int = 2):
    diag = json.loads(Path(files["diagnosis"]).read_text())
    ladder = pd.read_parquet(files["ladder"])
    unit = diag["unit"]
    b = diag["baseline"]
    doc.heading(f"Campaign '{campaign}' ({UNIT_NAMES[unit]})", level)
    noise = diag.get("noise_arcmin")
    doc.text(f"Measurements: {lit(diag['measurements'])}, {diag['n_specimens']} specimens, {diag['n_points']} values "
             f"({lit(diag['form'])} form)" + (f", stated noise {fmt(noise, 4)} arcmin" if noise else ", no noise stated")
             + f". Model: our FE model on a mesh of {diag['mesh']['elements_over_height']} × "
             f"{diag['mesh']['elements_over_thickness']} elements per tooth"
             + (f", with {lit(', '.join(diag['model']['fixed']))} switched on" if diag["model"]["fixed"] else "") + ". "
             + f"Candidates tried: {lit(', '.join(sorted(r['effect'] for r in diag['ranking'])))}.")
    doc.heading("Where the model fails", level + 1)
    rows = [["RMSE", fmt(b["rmse_arcmin"], 4)], ["bias (mean S − D)", fmt(b["bias_arcmin"], 4)],
            ["largest |E|", fmt(b["max_abs_arcmin"], 4)], ["worst specimen", lit(b["worst_specimen"])]]
    if b.get("u_val_arcmin") is not None:
        rows += [["u_val (V&V 20)", fmt(b["u_val_arcmin"], 4)],
                 ["points with |E| > 2 u_val", f"{fmt(100 * b['share_beyond_2uval'], 1)} %"]]
    doc.table(["comparison error E = S − D", "arcmin"], rows, "The campaign's model against the measurements.")
    doc.table(["specimen", "RMSE", "bias", "largest |E|"],
              [[lit(w["specimen_id"]), fmt(w["rmse_arcmin"], 4), fmt(w["bias_arcmin"], 4), fmt(w["max_abs_arcmin"], 4)]
               for w in diag["worst_specimens"]], "The specimens where the model fails worst (arcmin).")
    if diag["residual_tests"]:
        doc.table(["test on the residuals", "p-value", "small p means"],
                  [[lit(t["test"]), fmt(t["p_value"], 3), lit(t["meaning"])] for t in diag["residual_tests"]],
                  "statsmodels tests: a small p-value is a pattern in the error that the model does not explain.")
    doc.figure(files["measured_png"], "Measured against predicted: the campaign's model and the model with the found "
               "effects switched on (calibrated values; table interpolation).")
    doc.figure(files["residuals_png"], "Residuals D − S against each input (specimen means) and along the test.")
    doc.heading("Which effect is missing", level + 1)
    for rnd in diag["rounds"]:
        cur = "the campaign's model" if not rnd["model_effects"] else "the model with " + ", ".join(
            lit(e) for e in rnd["model_effects"])
        rows = []
        for r in rnd["ranking"]:
            (pname, val), = r["params"].items()
            sd = r.get("param_sd")
            rows.append([lit(r["effect"]), f"{lit(pname)} = {fmt(val, 4)}" + (f" ± {fmt(sd, 2)}" if sd is not None else "")
                         + (" (bound)" if r.get("at_bound") else "") + (" (off)" if r.get("calibrated_off") else ""),
                         fmt(r["rmse_arcmin"], 4), fmt(r["delta_bic"], 1), fmt(r["loo_rmse_arcmin"], 4),
                         fmt(r["signature_match"], 2), "yes" if r["pays"] else "no"])
        doc.table(["effect", "calibrated", "RMSE", "ΔBIC", "LOO RMSE", "match", "pays"], rows,
                  f"Round {rnd['round']}: every candidate calibrated on top of {cur} (RMSE "
                  f"{fmt(rnd['current_rmse_arcmin'], 4)} arcmin). Pays: ΔBIC ≤ −10 and a lower leave-one-specimen-out "
                  "error; match: cosine between the change the effect makes and the residual (1 = same pattern).")
        v = rnd["verdict"]
        if v["missing_effect"] is None:
            doc.text(f"Round {rnd['round']}: *no missing effect found.* No candidate lowers the error by more than "
                     "the data's scatter can explain (ΔBIC above −10, or no gain when a specimen is left out).")
        else:
            best = next(r for r in rnd["ranking"] if r["effect"] == v["missing_effect"])
            ties = v["indistinguishable_from"]
            txt = (f"Round {rnd['round']}: the model misses {_effect_sentence(best)}. Switched on, it lowers the error "
                   f"from {fmt(rnd['current_rmse_arcmin'], 4)} to {fmt(best['rmse_arcmin'], 4)} arcmin (ΔBIC "
                   f"{fmt(best['delta_bic'], 1)}: very strong evidence), also for specimens left out of the fit, "
                   f"and the change it makes lines up with the residual (match {fmt(best['signature_match'], 2)}). "
                   f"Its signature: {lit(best['signature'])}.")
            if ties:
                txt += (f" The data cannot tell it from {lit(', '.join(ties))}: their signatures coincide here, so the "
                        "choice between them needs another test (different torque levels, temperatures or parts).")
            if best.get("at_bound"):
                txt += " Its best value sits on the bound of its range: treat it as a stand-in, not an explanation."
            doc.text(txt)
    _refinement_part(doc, diag)
    _detectability_part(doc, diag, level + 1)
    doc.heading("Adding it: the error ladder", level + 1)
    doc.table(["rung", "model", "RMSE", "bias", "largest |E|", "ΔBIC"],
              [[str(r["rung"]), lit(r["model"]), fmt(r["rmse_arcmin"], 4), fmt(r["bias_arcmin"], 4),
                fmt(r["max_abs_arcmin"], 4), fmt(r["delta_bic"], 1)] for r in ladder.to_dict("records")],
              "Each rung re-solved with the FE model (not interpolated): the found effects switched on at their "
              "calibrated values. ΔBIC against the first rung." + (f" Stated noise: {fmt(noise, 4)} arcmin." if noise else ""))
    doc.figure(files["ladder_png"], "The error falling rung by rung.", width="75%")
    for name, note in diag.get("notes", {}).items():
        doc.text(f"Note on {lit(name)}: {lit(note)}.")


def full_report(files: dict[str, str], studies: dict[str, dict], data_dir, provenance: dict, out,
                assumptions: list[dict] | None = None, fe_settings: dict | None = None,
                campaigns: list[str] | None = None) -> Path:
    """``results/report.pdf``: the paper replication, then our FE model and its studies.

    ``files`` keys are ``{study}__{unit}__{key}``; ``studies`` maps study name -> its config.
    """
    paper_studies = [s for s, c in studies.items() if c["source"] == "paper"]
    fe_studies = [s for s, c in studies.items() if c["source"] == "fe"]
    doc = Document("hdwf: lost motion of harmonic drives", "Paper replication, our FE model and its studies",
                   provenance)
    doc.text("Part I reproduces the statistics of Majchrák et al. from their own FEA tables; Part II solves the same "
             "lost-motion test with our FE model, at our own optimal Latin hypercube (`fe`) and at the paper's design "
             "points (`fe_at_paper`), and runs the same chain on it. Every number below was computed by the workflow "
             "from the artefacts under `results/`.")
    with tempfile.TemporaryDirectory(prefix="hdwf-figs-") as tmp:
        tmp = Path(tmp)
        for study in paper_studies:
            units, f, cfg = studies[study]["units"], _sub(files, study), studies[study]
            doc.heading(f"Part I — the paper's FEA tables (study '{study}')", 1)
            _inputs_section(doc, units, data_dir, cfg, 2)
            _designs_section(doc, units, f, 2)
            _correlation_section(doc, units, f, 2)
            _surrogate_section(doc, units, f, 2)
            _sobol_section(doc, units, f, 2)
            _comparison_section(doc, units, f, data_dir, cfg, 2)
            doc.pagebreak()
        if fe_studies:
            doc.heading("Part II — our FE model", 1)
            pics = {UNIT_NAMES[k.split("__")[1]]: v for k, v in files.items() if k.endswith("__deformed_png")}
            _fe_model_section(doc, assumptions, pics, fe_settings, 2)
            conv = [s for s in fe_studies if any(k.startswith(f"{s}__") and k.endswith("__convergence") for k in files)]
            for study in conv:
                _convergence_section(doc, studies[study]["units"], _sub(files, study), 2)
            first = fe_studies[0]  # curves of one study are enough to show the test
            _curves_section(doc, studies[first]["units"], _sub(files, first), tmp, 2)
            at_paper = [s for s in fe_studies if studies[s].get("designs") == "paper"]
            if at_paper and paper_studies:
                units = [u for u in studies[at_paper[0]]["units"] if u in studies[paper_studies[0]]["units"]]
                _agreement_section(doc, units, _sub(files, paper_studies[0]), _sub(files, at_paper[0]), tmp, 2)
            all_units = sorted({u for s in fe_studies for u in studies[s]["units"]}, key=["hd42", "hd120"].index)
            _indices_vs_paper_section(doc, all_units, data_dir, {s: _sub(files, s) for s in paper_studies + fe_studies}, 2)
            for study in fe_studies:
                units, f = studies[study]["units"], _sub(files, study)
                doc.pagebreak()
                doc.heading(f"Study '{study}'", 2)
                _correlation_section(doc, units, f, 3)
                _surrogate_section(doc, units, f, 3)
                _sobol_section(doc, units, f, 3)
        if campaigns:
            doc.pagebreak()
            doc.heading("Part III — the model against measurements", 1)
            doc.text("Each campaign holds the FE model against a measurement file, shows where it fails, calibrates "
                     "every candidate physical effect (each a change to the FE model), names the missing one only "
                     "when it pays beyond the noise, and re-solves the model with it switched on "
                     "(docs/validation.md).")
            for c in campaigns:
                _validation_section(doc, c, {k.split("__", 2)[2]: v for k, v in files.items()
                                             if k.startswith(f"validation__{c}__")}, 2)
        return doc.compile(out)
