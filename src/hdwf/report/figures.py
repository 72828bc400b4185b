"""Figures of the study, in the paper's forms (Figs. 6–9, 13–14), of the FE model (curves, agreement,
deformed mesh) and of the validation campaigns, each written atomically as a PNG file."""

from __future__ import annotations

import json
from contextlib import contextmanager
from contextvars import ContextVar

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.collections import PolyCollection
from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator, NullFormatter
from scipy.optimize import isotonic_regression

from hdwf import PARAMETER_COLUMNS, PARAMETER_LABELS, PARAMETERS
from hdwf.common.io import atomic_path
from hdwf.fe.bodies import Material
from hdwf.fe.stress import von_mises_stress
from hdwf.study.knee import HingeFit

# Files only, never a window: the same backend on every machine, whatever MPLBACKEND says.
matplotlib.use("Agg")

# No "Software" chunk: the bytes hang on the data and on the provenance stamped (``stamped``:
# config hash, commit, package versions), not on matplotlib writing its own name and version.
_PNG_META = {"Software": None}
PROVENANCE_TEXT_KEY = "hdwf.provenance"
_provenance: ContextVar[str | None] = ContextVar("figure_provenance", default=None)


@contextmanager
def stamped(provenance: dict | None):
    """Figures saved inside the block carry ``provenance`` (JSON) in the PNG text chunk
    ``hdwf.provenance``, as a Parquet artefact carries it in its metadata."""
    token = _provenance.set(json.dumps(provenance, sort_keys=True) if provenance else None)
    try:
        yield
    finally:
        _provenance.reset(token)


def _save(fig, path):
    meta, provenance = dict(_PNG_META), _provenance.get()
    if provenance is not None:
        meta[PROVENANCE_TEXT_KEY] = provenance
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=150, format="png", metadata=meta, bbox_inches="tight")
    plt.close(fig)


def _symbol(p):
    """An input's symbol in matplotlib math, e.g. ``$r_{FS}$``."""
    return f"${PARAMETER_LABELS[p].replace('_', '_{') + ('}' if '_' in PARAMETER_LABELS[p] else '')}$"


def _label(p):
    return f"{_symbol(p)} (mm)"


def correlation_figure(designs: pd.DataFrame, corr: pd.DataFrame, title: str, path) -> None:
    """Φ against each input with the Pearson line and a monotone (rank) trend, as Figs. 6/7.

    Parameters
    ----------
    designs
        The study's lost-motion table (inputs and ``lost_motion_arcmin``).
    corr
        Its correlation table (``pearson_r``, ``spearman_rho`` per parameter).
    title, path
        The figure's title and PNG file.
    """
    y = designs["lost_motion_arcmin"].to_numpy(float)
    # two rows of three at page width, so that ticks and legend stay legible; the sixth panel
    # holds the legend, clear of the data
    fig, grid = plt.subplots(2, 3, figsize=(10, 6.2), sharey=True, layout="constrained")
    axes, legend_ax = grid.ravel()[:5], grid.ravel()[5]
    for ax, p, col in zip(axes, PARAMETERS, PARAMETER_COLUMNS):
        x = designs[col].to_numpy(float)
        ok = np.isfinite(y)
        ax.plot(x[ok], y[ok], "o", mfc="none", color="tab:blue", label="Φ")
        slope, icpt = np.polyfit(x[ok], y[ok], 1)
        xs = np.linspace(x.min(), x.max(), 50)
        ax.plot(xs, icpt + slope * xs, "-", color="tab:red", label="Pearson (linear)")
        # Spearman measures a monotone relation: draw the best monotone (isotonic) fit.
        rho = float(corr.set_index("parameter").loc[p, "spearman_rho"])
        order = np.argsort(x[ok])
        mono = isotonic_regression(y[ok][order], increasing=rho >= 0).x
        ax.plot(x[ok][order], mono, "-", color="black", lw=1, label="Spearman (monotone fit)")
        r = float(corr.set_index("parameter").loc[p, "pearson_r"])
        ax.set_title(f"r = {r:.3f}, ρ = {rho:.3f}", fontsize=9)
        ax.set_xlabel(_label(p))
        ax.ticklabel_format(axis="x", useOffset=False)
        ax.xaxis.set_major_locator(MaxNLocator(4))
        ax.tick_params(labelsize=9)
        ax.grid(alpha=0.3)
    for ax in grid[:, 0]:
        ax.set_ylabel("lost motion Φ (arcmin)")
    legend_ax.axis("off")
    legend_ax.legend(*axes[0].get_legend_handles_labels(), loc="center", fontsize=10)
    fig.suptitle(title)
    _save(fig, path)


def surrogate_figure(designs: pd.DataFrame, fitted: np.ndarray, title: str, path) -> None:
    """Data (circles) and surrogate (asterisks) against each input, as Figs. 8/9, plus a parity plot.

    Parameters
    ----------
    designs
        The designs the surrogate was fitted to.
    fitted
        The surrogate's values at those designs.
    title, path
        The figure's title and PNG file.
    """
    y = designs["lost_motion_arcmin"].to_numpy(float)
    fig, grid = plt.subplots(2, 3, figsize=(10, 6.2), layout="constrained")   # legible at page width
    axes = grid.ravel()
    for ax, p, col in zip(axes, PARAMETERS, PARAMETER_COLUMNS):
        x = designs[col].to_numpy(float)
        ax.plot(x, y, "o", mfc="none", color="tab:blue", label="data")
        ax.plot(x, fitted, "*", color="tab:red", label="quadratic")
        ax.set_xlabel(_label(p))
        ax.ticklabel_format(axis="x", useOffset=False)
        ax.xaxis.set_major_locator(MaxNLocator(4))
        ax.tick_params(labelsize=9)
        ax.grid(alpha=0.3)
    for ax in grid[:, 0]:
        ax.set_ylabel("Φ (arcmin)")
    axes[0].legend(fontsize=9)
    ax = axes[5]
    lim = [min(y.min(), fitted.min()), max(y.max(), fitted.max())]
    ax.plot(lim, lim, "-", color="grey", lw=0.8)
    ax.plot(y, fitted, "o", color="tab:purple", ms=4)
    ax.set_xlabel("data Φ (arcmin)")
    ax.set_ylabel("surrogate Φ (arcmin)")
    ax.set_title("parity", fontsize=9)
    fig.suptitle(title)
    _save(fig, path)


def sobol_convergence_figure(sobol: pd.DataFrame, title: str, path) -> None:
    """S1 and ST against N for each sampler, one panel per input, exact values as thick lines
    (the paper's Figs. 13/14 with the inputs apart: 30 lines in two panels could not be told apart).

    Parameters
    ----------
    sobol
        The study's Sobol' table (exact values and each sampler's estimates by N).
    title, path
        The figure's title and PNG file.
    """
    exact = sobol[sobol["sampler"] == "exact"].set_index("parameter")
    est = sobol[sobol["sampler"] != "exact"]
    styles = {"lhs": ":", "halton": "--", "sobol": "-"}
    colors = {"S1": "tab:blue", "ST": "tab:red"}
    names = {"S1": "first order $S_i$", "ST": "total effect $S_{Ti}$"}
    fig, grid = plt.subplots(2, 3, figsize=(10, 6.2), layout="constrained")
    axes, legend_ax = grid.ravel()[:5], grid.ravel()[5]
    for ax, p in zip(axes, PARAMETERS):
        for idx in ("S1", "ST"):
            for sampler, sub in est[est["parameter"] == p].groupby("sampler"):
                ax.plot(sub["n"], sub[idx], styles.get(sampler, "-"), color=colors[idx], lw=1,
                        marker="o" if sampler == "sobol" else None, ms=2.5, label=f"{names[idx]}, {sampler}")
            ax.axhline(exact.loc[p, idx], color=colors[idx], lw=3.0, alpha=0.3, label=f"{names[idx]}, exact")
        ax.set_xscale("log", base=2)
        ax.set_title(_symbol(p), fontsize=10)
        ax.tick_params(labelsize=8)
        ax.grid(alpha=0.3)
    for ax in grid[1, :2]:
        ax.set_xlabel("base sample size N")
    grid[0, 2].set_xlabel("base sample size N")
    for ax in grid[:, 0]:
        ax.set_ylabel("index")
    legend_ax.axis("off")
    legend_ax.legend(*axes[0].get_legend_handles_labels(), loc="center", fontsize=8)
    fig.suptitle(title)
    _save(fig, path)


def curves_figure(curves: pd.DataFrame, lost_motion: pd.DataFrame, design_ids: list[str], title: str, path) -> None:
    """Torque–twist curves of a few designs (the paper's Fig. 1 measured in our model).

    Parameters
    ----------
    curves
        The study's torque–twist curves (``curves.parquet``).
    lost_motion
        Its lost-motion table, for the legend.
    design_ids
        The designs drawn.
    title, path
        The figure's title and PNG file.
    """
    fig, ax = plt.subplots(figsize=(6.5, 4))
    lm = lost_motion.set_index("design_id")
    for did in design_ids:
        c = curves[curves["design_id"] == did].sort_values("step")
        ax.plot(c["twist_arcmin"], c["torque_Nm"], "-o", ms=3,
                label=f"{did}: Φ = {lm.loc[did, 'lost_motion_arcmin']:.3f} arcmin")
    ax.axhline(0, color="grey", lw=0.5)
    ax.axvline(0, color="grey", lw=0.5)
    ax.set_xlabel("FS twist (arcmin)")
    ax.set_ylabel("output torque (N·m)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10)
    _save(fig, path)


def agreement_figure(pairs: dict[str, tuple[np.ndarray, np.ndarray]], title: str, path) -> None:
    """Our Φ against the paper's Φ at the same design points, one panel per drive.

    Parameters
    ----------
    pairs
        Panel title -> (the paper's Φ, ours) at the same designs.
    title, path
        The figure's title and PNG file.
    """
    fig, axes = plt.subplots(1, len(pairs), figsize=(5.2 * len(pairs), 4.2), squeeze=False, layout="constrained")
    for ax, (label, (paper, ours)) in zip(axes[0], pairs.items()):
        ok = np.isfinite(ours)
        ax.plot(paper[ok], ours[ok], "o", mfc="none")
        slope, icpt = np.polyfit(paper[ok], ours[ok], 1)
        xs = np.linspace(paper.min(), paper.max(), 20)
        sign = "−" if icpt < 0 else "+"
        ax.plot(xs, icpt + slope * xs, "-", color="tab:red", lw=1,
                label=f"fit: ours = {slope:.2f}·paper {sign} {abs(icpt):.2f}")
        # the level is read against equality, which the fit alone does not show
        ax.plot(xs, xs, "--", color="0.4", lw=1, label="ours = paper")
        ax.set_xlabel("paper's Ansys FEA Φ (arcmin)")
        ax.set_ylabel("hdwf FE Φ (arcmin)")
        ax.set_title(label, fontsize=10)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    fig.suptitle(title)
    _save(fig, path)


def knee_figure(panels: dict[str, dict[str, tuple[np.ndarray, np.ndarray, HingeFit]]], title: str, path) -> None:
    """Φ against the clearance s with each model's hinge fit, one panel per drive; a log Φ axis
    only where a panel's Φ spans more than ten times (a locked design beside open ones), else
    linear, where a hinge reads as the two straight pieces it is.

    Parameters
    ----------
    panels
        Panel title -> {model name: (s in µm, Φ in arcmin, its ``hdwf.study.knee.HingeFit``)}.
    title, path
        The figure's title and PNG file.
    """
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.2), squeeze=False, layout="constrained")
    for ax, (label, models) in zip(axes[0], panels.items()):
        for (name, (s, phi, fit)), colour in zip(models.items(), ("tab:blue", "tab:red")):
            ax.plot(s, phi, "o", mfc="none", color=colour, label=f"{name} (R² {fit.r2:.2f})")
            xs = np.linspace(min(s.min(), fit.knee_um), s.max(), 200)
            ys = fit.predict(xs)
            ax.plot(xs[ys > 0], ys[ys > 0], "-", color=colour, lw=1)
            if fit.knee_um > s.min():
                ax.axvline(fit.knee_um, color=colour, ls=":", lw=0.8)
        phis = np.concatenate([phi for _, phi, _ in models.values()])
        phis = phis[np.isfinite(phis) & (phis > 0)]
        if len(phis) and phis.max() > 10 * phis.min():
            ax.set_yscale("log")
        ax.set_xlabel("clearance $s = r_{FS} + r_{CS}$ + weighted radial shortfall (µm)")
        ax.set_ylabel("Φ (arcmin)")
        ax.set_title(label, fontsize=10)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3, which="both")
    fig.suptitle(title)
    _save(fig, path)


def deformed_figure(mesh, fields: dict, material: Material, title: str, path, half_width_mm: float,
                    xlim: tuple[float, float], magnify: float = 1.0) -> None:
    """FS and CS near the major axis (+x) in the deformed state at +T, true scale.

    Colour: the von Mises stress the test torque adds (of u at +T minus u after mounting the
    wave generator), in MPa: where the load goes. A displacement would not show it: near the
    major axis the FS moves some micrometres almost alike everywhere (the ring's own
    distortion under torque), whatever its teeth carry. Bearing rings are drawn grey.

    Parameters
    ----------
    mesh
        The drive's mesh (``hdwf.drive.design``), half or full.
    fields
        Displacements per state (``plus``, ``wg``) and body.
    material
        The bodies' E and ν.
    title, path
        The figure's title and PNG file.
    half_width_mm
        Half the height of the window about the major axis.
    xlim
        The radial window (mm).
    magnify
        Scale of the displacements drawn.
    """
    fig, ax = plt.subplots(figsize=(8, 5.5))
    plus, wg = fields["plus"], fields["wg"]
    values, polys = [], []
    ymax = half_width_mm
    # A half model (180° point symmetry) holds angles 0..π; the rest is its image under p -> -p, u -> -u.
    images = (1.0, -1.0) if getattr(mesh, "symmetry", "full") == "half" else (1.0,)
    for name, body in mesh.bodies.items():
        # the image p -> -p, u -> -u has the same strain: one stress field serves both
        added = (von_mises_stress(body.mesh, plus[name] - wg[name], material.E, material.nu)
                 if name in ("fs", "cs") else None)
        for sgn in images:
            p, t = sgn * body.mesh.p, body.mesh.t
            x = p + magnify * sgn * plus[name]
            corners = x[:, t]     # drawn if its box, where it is drawn, meets the window (large ring elements too)
            keep = ((corners[0].max(axis=0) > xlim[0]) & (corners[0].min(axis=0) < xlim[1])
                    & (corners[1].max(axis=0) > -ymax) & (corners[1].min(axis=0) < ymax))
            tri = x[:, t[:, keep]].transpose(2, 1, 0)  # (n, 3, 2)
            if added is not None:
                polys.append(tri)
                values.append(added[keep])
            else:
                ax.add_collection(PolyCollection(tri, facecolors="0.85", edgecolors="0.6", linewidths=0.1))
    values = np.concatenate(values)
    # contact corners carry point-load peaks that grow as the mesh is refined: the scale stops at the
    # 99th percentile so the load paths through the teeth stay visible
    coll = PolyCollection(np.concatenate(polys), array=values, cmap="viridis", edgecolors="k", linewidths=0.05,
                          clim=(0.0, float(np.percentile(values, 99))))
    ax.add_collection(coll)
    fig.colorbar(coll, ax=ax, extend="max", label="von Mises stress added by the test torque (MPa)")
    ax.set_xlim(*xlim)
    ax.set_ylim(-ymax, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm), major axis")
    ax.set_ylabel("y (mm)")
    ax.set_title(title, fontsize=10)
    _save(fig, path)


def measured_vs_predicted_figure(points: pd.DataFrame, title: str, path) -> None:
    """Measured against predicted, before (campaign model) and after (found effects on).

    Parameters
    ----------
    points
        The campaign's points: measured ``D``, predicted ``S_model`` and ``S_final``.
    title, path
        The figure's title and PNG file.
    """
    # each panel its own range: the found effects' errors are often a twentieth of the model's
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
    D = points["D"].to_numpy(float)
    for ax, col, name in zip(axes, ("S_model", "S_final"), ("campaign model", "with the found effects")):
        S = points[col].to_numpy(float)
        lo, hi = np.nanmin(np.concatenate([D, S])), np.nanmax(np.concatenate([D, S]))
        pad = 0.05 * (hi - lo or 1.0)
        rmse = float(np.sqrt(np.mean((S - D) ** 2)))
        ax.plot([lo - pad, hi + pad], [lo - pad, hi + pad], "k-", lw=0.8)
        ax.plot(S, D, "o", ms=3, alpha=0.6)
        ax.set_title(f"{name}: RMSE {rmse:.4f} arcmin")
        ax.set_xlabel("predicted (arcmin)")
    axes[0].set_ylabel("measured (arcmin)")
    fig.suptitle(title)
    _save(fig, path)


def residual_figure(points: pd.DataFrame, title: str, path) -> None:
    """Residual D − S of the campaign model against each input (specimen means) and, for
    curves, along the test by torque and branch; the found effects' residual beside it.

    Parameters
    ----------
    points
        The campaign's points (``D``, ``S_model``, ``S_final``, inputs, and for curves
        ``torque_Nm`` and ``branch``).
    title, path
        The figure's title and PNG file.
    """
    curve = "torque_Nm" in points.columns and points["torque_Nm"].notna().any()
    panels = len(PARAMETERS) + (1 if curve else 0)
    # three panels a row: six in one row left tick labels of 4 pt on a printed page
    nrows = -(-panels // 3)
    fig, grid = plt.subplots(nrows, 3, figsize=(9, 3.2 * nrows), sharey=True, layout="constrained", squeeze=False)
    axes = list(grid.ravel()[:panels])
    spares = list(grid.ravel()[panels:])
    for spare in spares:
        spare.set_visible(False)
    r0 = points["D"] - points["S_model"]
    r1 = points["D"] - points["S_final"]
    spec = points.assign(r0=r0, r1=r1).groupby("specimen_id").agg(
        r0=("r0", "mean"), r1=("r1", "mean"), **{c: (c, "first") for c in PARAMETER_COLUMNS})
    for ax, p, col in zip(axes, PARAMETERS, PARAMETER_COLUMNS):
        ax.plot(spec[col], spec["r0"], "o", mfc="none", label="campaign model")
        ax.plot(spec[col], spec["r1"], "x", label="with found effects")
        ax.axhline(0, color="k", lw=0.6)
        ax.set_xlabel(_label(p))
        ax.ticklabel_format(axis="x", useOffset=False)
        ax.tick_params(axis="x", labelrotation=30)
    for row in grid:
        row[0].set_ylabel("mean residual D − S (arcmin)")
    if curve:
        ax = axes[-1]
        pts = points.assign(r0=r0)
        for br, g in pts.groupby("branch", sort=True) if "branch" in pts else [("all", pts)]:
            ax.plot(g["torque_Nm"], g["r0"], ".", ms=3, label=br)
        ax.axhline(0, color="k", lw=0.6)
        ax.set_xlabel("torque (N m)")
        ax.set_title("along the curve (campaign model)", fontsize=9)
    # the legend clear of the data: in a spare cell, else one row under the panels
    handles, labels = [], []
    for ax in (axes[0], axes[-1]) if curve else (axes[0],):
        h, lab = ax.get_legend_handles_labels()
        handles, labels = handles + h, labels + lab
    if spares:
        spares[0].set_visible(True)
        spares[0].axis("off")
        spares[0].legend(handles, labels, loc="center", fontsize=9)
    else:
        fig.legend(handles, labels, loc="outside lower center", ncol=len(labels), fontsize=8)
    fig.suptitle(title)
    _save(fig, path)


def _rung_tick(model: str) -> str:
    """A ladder rung's tick: the baseline and campaign model by name, a found effect's rung by the
    effect it adds (``ladder_variants`` labels it 'with a, b, c', cumulative)."""
    if model.startswith("with "):
        return "+ " + model[len("with "):].split(", ")[-1]
    return model


def ladder_figure(ladder: pd.DataFrame, noise_arcmin: float | None, title: str, path) -> None:
    """RMSE of each model variant of the ladder, falling rung by rung.

    Parameters
    ----------
    ladder
        The campaign's ladder (``model``, ``rmse_arcmin`` per rung).
    noise_arcmin
        The stated measurement noise, drawn as a line; none when ``None``.
    title, path
        The figure's title and PNG file.
    """
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    x = np.arange(len(ladder))
    rmse = ladder["rmse_arcmin"].to_numpy(float)
    ax.plot(x, rmse, "o-", color="tab:blue", label="RMSE (actual solves)")
    for xi, r in zip(x[np.isfinite(rmse)], rmse[np.isfinite(rmse)]):   # a failed rung has no error
        ax.annotate(f"{r:.3g}", (xi, r), textcoords="offset points", xytext=(5, 5), fontsize=8)
    if noise_arcmin:
        ax.axhline(noise_arcmin, color="tab:gray", ls="--", label=f"noise {noise_arcmin:.3g} arcmin")
    # the rungs are cumulative: each tick names what its rung adds (the full list overlapped)
    ax.set_xticks(x, [_rung_tick(m) for m in ladder["model"]], fontsize=8)
    ax.set_xlim(-0.3, len(x) - 0.4)
    ax.set_xlabel("each rung adds the effect it names to the rung before", fontsize=8)
    ax.set_ylabel("RMSE (arcmin)")
    shown = np.concatenate([rmse[np.isfinite(rmse) & (rmse > 0)], [noise_arcmin] if noise_arcmin else []])
    if shown.size and shown.max() > 10 * shown.min():
        # a fall of 10x or more: on a linear axis the last rungs sit on the floor, indistinguishable
        ax.set_yscale("log")
        ax.set_ylim(shown.min() / 1.6, shown.max() * 1.8)
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
    else:
        top = float(shown.max()) if shown.size else 0.0
        ax.set_ylim(0, 1.15 * top if top > 0 else None)   # room for the labels
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    _save(fig, path)
