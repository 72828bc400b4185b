"""How far our lost motion agrees with the paper's at the same designs, and how far the mesh moves that.

``agreement``: level (median ratio ours / paper), rank (Spearman ρ) and shape (R² of a linear fit,
Pearson r squared) over the designs both have.

``agreement_under_mesh_scatter``: the same figures after each of our Φ is moved by a relative change
drawn from the mesh changes measured on this drive (``convergence.parquet``'s ``rel_change_fine``:
default mesh against a 1.25× finer one) with a random sign, many times (seeded); with
``slope_weights`` also the ratio of a least-squares slope, ours over the paper's (dΦ/dr_FS,
``hdwf.study.knee.offset_slope_weights``). The band of the draws, and the share of draws that meet a
target (``ScatterBand.share``), say how much of a gap to a target the mesh scatter alone could close
or open. It is a sensitivity, not a confidence interval: the values already carry one draw of that
scatter, and the changes of other designs of the same drive stand in for those of these designs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import stats

#: seeds the draws of ``agreement_under_mesh_scatter`` (same artefacts, same band)
SCATTER_SEED = 20261126


@dataclass(frozen=True)
class Agreement:
    """Level, rank and shape of ours against the paper's Φ over ``n`` designs."""

    n: int
    median_ratio: float
    spearman: float
    spearman_p: float
    r2: float


@dataclass(frozen=True)
class ScatterBand:
    """Quantiles (``q``, e.g. 5 and 95 %) of the agreement figures over ``draws`` perturbed copies,
    and every draw's figures (``samples``, by figure name) for ``share``."""

    q: tuple[float, float]
    draws: int
    median_ratio: tuple[float, float]
    spearman: tuple[float, float]
    r2: tuple[float, float]
    slope_ratio: tuple[float, float] | None = None   # ours / the paper's least-squares slope, with slope_weights
    samples: dict[str, np.ndarray] = field(default_factory=dict, repr=False, compare=False)

    def share(self, figure: str, low: float = -np.inf, high: float = np.inf) -> float:
        """The fraction of the draws whose ``figure`` lies in [low, high], e.g. meets a target.
        Exact, where the quantiles are rounded: a rank figure takes few values."""
        if figure not in self.samples:
            raise KeyError(f"no draws of {figure!r}; there are {sorted(self.samples)}")
        values = self.samples[figure]
        return float(np.mean((values >= low) & (values <= high)))


def _paired(paper: np.ndarray, ours: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    paper, ours = np.asarray(paper, float), np.asarray(ours, float)
    if paper.shape != ours.shape or paper.ndim != 1:
        raise ValueError(f"paper and ours must be 1D arrays of one length, got shapes {paper.shape}, {ours.shape}")
    keep = np.isfinite(paper) & np.isfinite(ours)
    if keep.sum() < 3:
        raise ValueError(f"need at least 3 designs with both values, got {int(keep.sum())}")
    return paper[keep], ours[keep]


def agreement(paper, ours) -> Agreement:
    """Agreement of ``ours`` with ``paper`` (Φ per design, same order); designs missing either are left out."""
    paper, ours = _paired(paper, ours)
    rho = stats.spearmanr(paper, ours)
    return Agreement(n=len(paper), median_ratio=float(np.median(ours / paper)), spearman=float(rho.statistic),
                     spearman_p=float(rho.pvalue), r2=float(stats.pearsonr(paper, ours).statistic ** 2))


def agreement_under_mesh_scatter(paper, ours, rel_changes, draws: int = 2000, q: tuple[float, float] = (0.05, 0.95),
                                 seed: int = SCATTER_SEED, slope_weights=None) -> ScatterBand:
    """The band of ``agreement`` when each of ``ours`` is multiplied by 1 ± a change drawn from ``rel_changes``.

    Parameters
    ----------
    paper, ours
        Φ per design, same order (designs missing either are left out).
    rel_changes
        Measured relative mesh changes (fractions; their sign is ignored, each draw gets a random one).
    draws
        Perturbed copies.
    q
        The quantiles reported.
    seed
        Seeds the draws.
    slope_weights
        Optional weights w (one per design, same order) with w · Φ a least-squares slope, e.g.
        dΦ/dr_FS (``hdwf.study.knee.offset_slope_weights``): the band then has ``slope_ratio``,
        our slope over the paper's. Needs every design to have both values.
    """
    if slope_weights is not None and not (np.isfinite(np.asarray(paper, float)).all()
                                          and np.isfinite(np.asarray(ours, float)).all()):
        raise ValueError("slope_weights need both values on every design")
    paper, ours = _paired(paper, ours)
    changes = np.abs(np.asarray(rel_changes, float))
    changes = changes[np.isfinite(changes)]
    if changes.size == 0:
        raise ValueError("no measured mesh change to draw from")
    if changes.max() >= 1.0:
        raise ValueError(f"a relative mesh change of {changes.max():g} (>= 1) would make a lost motion zero or negative")
    rng = np.random.default_rng(seed)
    factor = 1.0 + rng.choice(changes, (draws, len(ours))) * rng.choice((-1.0, 1.0), (draws, len(ours)))
    perturbed = ours * factor
    ratio = np.median(perturbed / paper, axis=1)
    # Spearman of each draw: Pearson of the ranks (the paper's ranks are fixed)
    rank_paper = stats.rankdata(paper)
    rho = np.array([np.corrcoef(rank_paper, stats.rankdata(row))[0, 1] for row in perturbed])
    r2 = np.array([np.corrcoef(paper, row)[0, 1] ** 2 for row in perturbed])

    def band(values: np.ndarray) -> tuple[float, float]:
        lo, hi = np.quantile(values, q)
        return float(lo), float(hi)

    samples = {"median_ratio": ratio, "spearman": rho, "r2": r2}
    if slope_weights is not None:
        w = np.asarray(slope_weights, float)
        if w.shape != ours.shape:
            raise ValueError(f"slope_weights must have one weight per design ({ours.size}), got shape {w.shape}")
        samples["slope_ratio"] = perturbed @ w / (w @ paper)
    return ScatterBand(q=tuple(q), draws=draws, median_ratio=band(ratio), spearman=band(rho), r2=band(r2),
                       slope_ratio=band(samples["slope_ratio"]) if "slope_ratio" in samples else None,
                       samples=samples)
