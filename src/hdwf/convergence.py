"""Mesh convergence: Richardson extrapolation and the grid convergence index (GCI).

Celik et al. (2008), "Procedure for estimation and reporting of uncertainty due to
discretization in CFD applications", J. Fluids Eng. 130, 078001 — the ASME procedure:
three meshes with representative sizes h1 < h2 < h3, apparent order p from a fixed-point
iteration, extrapolated value and GCI_fine = 1.25 e_a / (r^p - 1). Hand-written because it
is a dozen lines and no maintained package offers it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class GCIResult:
    p: float                 # apparent order of convergence (nan when not monotone)
    phi_extrapolated: float  # Richardson-extrapolated value (nan when not monotone)
    rel_change_fine: float   # |phi1 - phi2| / |phi1|: the two finest meshes
    gci_fine: float          # GCI of the fine mesh, relative (0.01 = 1 %)
    monotone: bool           # False for oscillatory or stalled convergence


def gci(h: tuple[float, float, float], phi: tuple[float, float, float], safety: float = 1.25,
        max_iter: int = 100) -> GCIResult:
    """GCI of three solutions ``phi`` on meshes of size ``h`` (fine, medium, coarse)."""
    h1, h2, h3 = h
    f1, f2, f3 = phi
    if not h1 < h2 < h3:
        raise ValueError(f"mesh sizes must be fine < medium < coarse, got {h}")
    r21, r32 = h2 / h1, h3 / h2
    e21, e32 = f2 - f1, f3 - f2
    rel = abs(e21 / f1) if f1 != 0 else math.inf
    if e21 == 0 or e32 == 0 or e32 / e21 < 0:
        # Oscillating or stalled: no order can be inferred; Celik recommends a bound from
        # the spread of the three solutions, with the safety factor 3 of Roache.
        spread = (max(phi) - min(phi)) / abs(f1) if f1 != 0 else math.inf
        return GCIResult(math.nan, math.nan, rel, 3.0 * spread / 2.0 if spread else 0.0, False)
    s = 1.0
    p = abs(math.log(abs(e32 / e21))) / math.log(r21)
    for _ in range(max_iter):
        q = math.log((r21 ** p - s) / (r32 ** p - s))
        p_new = abs(math.log(abs(e32 / e21)) + q) / math.log(r21)
        if abs(p_new - p) < 1e-10:
            p = p_new
            break
        p = p_new
    ext = (r21 ** p * f1 - f2) / (r21 ** p - 1.0)
    return GCIResult(p, ext, rel, safety * rel / (r21 ** p - 1.0), True)
