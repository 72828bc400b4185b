"""Mesh convergence: Richardson extrapolation and the grid convergence index (GCI).

Celik et al. (2008), "Procedure for estimation and reporting of uncertainty due to
discretization in CFD applications", J. Fluids Eng. 130, 078001 — the ASME procedure:
three meshes with representative sizes h1 < h2 < h3, apparent order p, extrapolated value
and GCI_fine = 1.25 e_a / (r^p - 1). Hand-written because it is a few lines and no
maintained package offers it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import brentq


@dataclass(frozen=True)
class GCIResult:
    p: float                 # apparent order of convergence (nan when it cannot be established)
    phi_extrapolated: float  # Richardson-extrapolated value (nan without an order)
    rel_change_fine: float   # |phi1 - phi2| / |phi1|: the two finest meshes
    gci_fine: float          # GCI of the fine mesh, relative (0.01 = 1 %)
    monotone: bool           # False for oscillatory or stalled convergence
    asymptotic: bool = True  # False when no order in [P_MIN, P_MAX] fits the three solutions
    note: str = ""


P_MIN, P_MAX = 0.5, 10.0
CONSERVATIVE_P = 1.0  # contact problems converge at about first order; assumed when p is unknown


def gci(h: tuple[float, float, float], phi: tuple[float, float, float], safety: float = 1.25) -> GCIResult:
    """GCI of three solutions ``phi`` on meshes of size ``h`` (fine, medium, coarse).

    The apparent order solves p ln r21 = |ln|e32/e21| + ln((r21^p - s)/(r32^p - s))| (Celik
    Eq. 5) by bracketing in [P_MIN, P_MAX]. Without a root there (oscillating, stalled or
    pre-asymptotic solutions) the GCI falls back to Roache's safety factor 3 with first order,
    and says so.
    """
    h1, h2, h3 = h
    f1, f2, f3 = phi
    if not h1 < h2 < h3:
        raise ValueError(f"mesh sizes must be fine < medium < coarse, got {h}")
    r21, r32 = h2 / h1, h3 / h2
    e21, e32 = f2 - f1, f3 - f2
    rel = abs(e21 / f1) if f1 != 0 else math.inf
    fallback = 3.0 * rel / (r21 ** CONSERVATIVE_P - 1.0)
    if e21 == 0 or e32 == 0 or e32 / e21 < 0:
        return GCIResult(math.nan, math.nan, rel, fallback, False, False,
                         "oscillating or stalled: GCI with safety factor 3 and first order")
    s = 1.0
    ratio = math.log(abs(e32 / e21))

    def residual(p):
        return p * math.log(r21) - abs(ratio + math.log((r21 ** p - s) / (r32 ** p - s)))

    grid = [P_MIN + k * (P_MAX - P_MIN) / 200 for k in range(201)]
    values = [residual(p) for p in grid]
    root = None
    for a, b, fa, fb in zip(grid, grid[1:], values, values[1:]):
        if fa == 0 or fa * fb < 0:
            root = a if fa == 0 else brentq(residual, a, b, xtol=1e-12)
            break
    if root is None:
        return GCIResult(math.nan, math.nan, rel, fallback, True, False,
                         f"not in the asymptotic range (no order in [{P_MIN}, {P_MAX}]): "
                         "GCI with safety factor 3 and first order")
    ext = (r21 ** root * f1 - f2) / (r21 ** root - 1.0)
    return GCIResult(root, ext, rel, safety * rel / (r21 ** root - 1.0), True, True, "")


def twist_resolution_arcmin(tol_gap_mm: float, base_radius_mm: float) -> float:
    """The smallest change of Φ between two solves that the contact tolerance resolves.

    A solve stops once no pair penetrates by more than ``tol_gap_mm``; a flank at base radius
    r_b turns by gap / r_b per unit of normal gap, so each twist θ(±T) is known to
    tol / r_b, Φ = θ(+T) − θ(−T) to 2 tol / r_b, and the difference of two Φ to 4 tol / r_b.
    """
    return 4.0 * tol_gap_mm / base_radius_mm * 180.0 * 60.0 / math.pi


def convergence_table(results: pd.DataFrame, resolution_arcmin: float | None = None) -> pd.DataFrame:
    """One row per design: Φ on the fine, medium and coarse mesh, the GCI and the fine change.

    ``results`` has columns design_id, refinement, h_mm (representative element size),
    lost_motion_arcmin.  With ``resolution_arcmin`` (``twist_resolution_arcmin``) each row also
    says whether the two finest meshes differ by no more than the solver resolves
    (``within_resolution``): a relative criterion cannot be met below that, at small Φ.
    """
    out = []
    levels = ("fine", "medium", "coarse")
    for design_id, sub in results.groupby("design_id", sort=True):
        sub = sub.sort_values("h_mm")  # fine first
        row = {"design_id": design_id}
        for k, r in zip(levels, sub.itertuples()):
            row.update({f"refinement_{k}": float(r.refinement), f"h_{k}_mm": float(r.h_mm),
                        f"phi_{k}_arcmin": float(r.lost_motion_arcmin)})
        phi = sub["lost_motion_arcmin"].to_numpy(float)
        if len(sub) < 2 or not np.isfinite(phi).all():
            row.update({"converged": False, "note": "a refinement failed or is missing"})
        else:
            row["rel_change_fine"] = float(abs(phi[1] - phi[0]) / abs(phi[0]))
            row["change_fine_arcmin"] = float(abs(phi[1] - phi[0]))
            row["converged"] = bool(row["rel_change_fine"] < 0.02)
            if resolution_arcmin is not None:
                row["resolution_arcmin"] = float(resolution_arcmin)
                row["within_resolution"] = bool(row["change_fine_arcmin"] <= resolution_arcmin)
            row["note"] = ""
            if len(sub) == 3:
                g = gci(tuple(sub["h_mm"]), tuple(phi))
                row.update({"gci_fine": g.gci_fine, "order_p": g.p, "phi_extrapolated_arcmin": g.phi_extrapolated,
                            "monotone": g.monotone, "asymptotic": g.asymptotic, "note": g.note})
        out.append(row)
    return pd.DataFrame(out)
